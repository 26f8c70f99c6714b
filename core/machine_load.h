#pragma once
// What else ran on the machine beside a run: its speed is reported with this beside it. Linux's 1-minute load
// average (/proc/loadavg: the processes running or waiting for a core, averaged with a one-minute decay) and the
// cores the toolkit may use.
namespace needle {

struct MachineLoad {
  double load_average_1min = -1;  // -1: unknown (no /proc/loadavg)
  int cores = 0;                  // hardware_threads()
};

MachineLoad machine_load();

}  // namespace needle
