// Checkpoints as a driver observer: every `every` seconds of the run, the next pass copies each
// point's state into a reused snapshot buffer inside its update loop (fold_pass), and a
// background thread writes from that snapshot while the passes go on. One checkpoint is in
// flight at most: while one is being written, the next waits for a later pass. finish() waits
// for the last one and rethrows what a write threw. The final image and state are the caller's,
// after the loop, so the last pass is not written here.
#pragma once

#include "app/checkpoint.h"
#include "app/driver.h"

#include <functional>
#include <future>
#include <vector>

namespace pb {

class CheckpointWriter : public PassObserver {
 public:
  // `write` runs on the background thread with a complete SavedRender (options and scene hash
  // as given here); it must not touch the Renderer's mutable state (Renderer::image(run, state)
  // of the snapshot is safe).
  using Write = std::function<void(const SavedRender&)>;
  CheckpointWriter(double every, RenderOptions options, uint64_t scene_hash, Write write);
  ~CheckpointWriter() override;

  std::vector<PointState>* snapshot_buffer(double run_seconds) override;
  void after_pass(const PassInfo& info) override;
  void finish() override;

  // Time the pass loop spent on checkpoints (waiting for the previous write, starting the
  // next), the background writes' wall time, and how many were written.
  double stall_seconds() const { return stall_; }
  double write_seconds() const { return write_; }
  uint64_t checkpoints() const { return written_; }

 private:
  void collect();  // waits for the write in flight, rethrows, takes the buffer back

  double every_;
  RenderOptions options_;
  uint64_t scene_hash_;
  Write write_fn_;
  std::vector<PointState> buffer_;
  std::future<std::vector<PointState>> pending_;
  bool handed_out_ = false;
  double last_ = 0.0;
  double stall_ = 0.0, write_ = 0.0;
  uint64_t written_ = 0;
};

}  // namespace pb
