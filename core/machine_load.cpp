#include "core/machine_load.h"

#include <fstream>

#include "core/parallel.h"

namespace needle {

MachineLoad machine_load() {
  MachineLoad m;
  m.cores = hardware_threads();
  std::ifstream in("/proc/loadavg");
  double one_minute = 0;
  if (in >> one_minute && one_minute >= 0) m.load_average_1min = one_minute;
  return m;
}

}  // namespace needle
