#include "plslam/core/resident_memory.h"

#include <fstream>

#include <unistd.h>

namespace plslam::core {

double resident_memory_mb() {
  std::ifstream in("/proc/self/statm");
  long total_pages = 0, resident_pages = 0;
  if (!(in >> total_pages >> resident_pages)) return -1;
  const long page = sysconf(_SC_PAGESIZE);
  return static_cast<double>(resident_pages) * static_cast<double>(page > 0 ? page : 4096) / (1024.0 * 1024.0);
}

}  // namespace plslam::core
