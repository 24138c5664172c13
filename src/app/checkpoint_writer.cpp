#include "app/checkpoint_writer.h"

#include "util/timer.h"

namespace pb {

CheckpointWriter::CheckpointWriter(double every, RenderOptions options, uint64_t scene_hash,
                                   Write write)
    : every_(every), options_(std::move(options)), scene_hash_(scene_hash), write_fn_(write) {}

CheckpointWriter::~CheckpointWriter() {
  if (pending_.valid()) pending_.wait();  // a failed write was already reported or is moot
}

void CheckpointWriter::collect() {
  const auto t = Clock::now();
  buffer_ = pending_.get();
  stall_ += seconds_since(t);
}

std::vector<PointState>* CheckpointWriter::snapshot_buffer(double run_seconds) {
  const bool idle =
      !pending_.valid() || pending_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  if (pending_.valid() && idle) collect();
  handed_out_ = every_ > 0.0 && idle && run_seconds - last_ >= every_;
  return handed_out_ ? &buffer_ : nullptr;
}

void CheckpointWriter::after_pass(const PassInfo& info) {
  if (!handed_out_ || info.stop != StopReason::None) return;
  handed_out_ = false;
  const auto t = Clock::now();
  last_ = info.run_seconds;
  SavedRender saved;
  saved.options = options_;
  saved.scene_hash = scene_hash_;
  saved.render = info.renderer.snapshot(std::move(buffer_));
  saved.schedule = info.schedule;
  pending_ = std::async(std::launch::async, [this, saved = std::move(saved)]() mutable {
    const auto t_write = Clock::now();
    write_fn_(saved);
    write_ += seconds_since(t_write);
    ++written_;
    return std::move(saved.render.states);
  });
  stall_ += seconds_since(t);
}

void CheckpointWriter::finish() {
  if (pending_.valid()) collect();
}

}  // namespace pb
