#include "util/memory.h"

#include <unistd.h>

#include <cstdio>
#include <fstream>

namespace pb {

namespace {

// The memory.max of this process's cgroup (v2: /proc/self/cgroup holds "0::/PATH"); 0 when
// there is none, it reads "max", or the files cannot be read.
uint64_t cgroup_limit() {
  std::ifstream groups("/proc/self/cgroup");
  std::string line;
  while (std::getline(groups, line)) {
    if (line.rfind("0::", 0) != 0) continue;
    std::ifstream max("/sys/fs/cgroup" + line.substr(3) + "/memory.max");
    uint64_t v = 0;
    if (max >> v) return v;
  }
  return 0;
}

}  // namespace

uint64_t machine_memory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  uint64_t ram = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
  const uint64_t group = cgroup_limit();
  if (group > 0 && (ram == 0 || group < ram)) ram = group;
  return ram;
}

uint64_t default_memory_budget() {
  const uint64_t ram = machine_memory();
  return ram > 0 ? ram / 4 * 3 : uint64_t(8) << 30;
}

std::string bytes_text(uint64_t bytes) {
  const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return std::to_string(bytes) + " bytes";
  double v = double(bytes);
  int u = -1;
  while (v >= 1024.0 && u < 5) {
    v /= 1024.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, v < 10.0 ? "%.1f %s" : "%.0f %s", v, units[u]);
  return buf;
}

}  // namespace pb
