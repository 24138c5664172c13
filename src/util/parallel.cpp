#include "util/parallel.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

namespace pb {

struct ThreadLimit::Impl {
  tbb::global_control control;
  explicit Impl(int n) : control(tbb::global_control::max_allowed_parallelism, size_t(n)) {}
};

ThreadLimit::ThreadLimit(int threads)
    : threads_(threads > 0 ? threads : tbb::info::default_concurrency()) {
  impl_ = std::make_unique<Impl>(threads_);
}

ThreadLimit::~ThreadLimit() = default;

}  // namespace pb
