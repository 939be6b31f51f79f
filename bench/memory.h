// What the end-to-end benchmarks share.
#pragma once

#include <fstream>

namespace pdvo::bench {

// Resident memory now, in MiB (from /proc/self/statm).
inline double ResidentMiB() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * 4096.0 / (1 << 20);
}

}  // namespace pdvo::bench
