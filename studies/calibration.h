#pragma once
// The calibration study behind `needle calibrate`: finds the tissue's Young's modulus (the one parameter the paper does not give)
// for which a needle's insertion ends at the measured deflection. Each evaluation is a full run of the
// paper's scene (DIR/runs/E_<value>MPa, reused when already there with the same scene); the first step
// assumes deflection proportional to E, the next ones are secant steps on the last two runs. Once the
// target is met, one more run at E (1 + sensitivity step) measures the local slope d delta / d E, unless
// a finished run already lies that close: one of this calibration's, or a run of the same scene at another E
// already in DIR/runs (an earlier calibration's, or one run beside it). Writes DIR/calibration.json (E, every run, the sensitivity)
// and DIR/calibration.png.
// The command (apps/calibrate_command.cpp) parses its flags into a CalibrationRequest and calls this.
#include <limits>
#include <string>

#include "runs/scene.h"

namespace needle {

struct CalibrationRequest {
  Scene scene;            // the needle's insertion at its starting E (the run defaults with the command's keys)
  std::string preset = "SB";  // the needle (SB, LMB, AMB or HMB), as the record names it
  double target_mm = std::numeric_limits<double>::quiet_NaN();    // the measured deflection at the end (SB: -1.14); required
  double start_E_MPa = std::numeric_limits<double>::quiet_NaN();  // NaN: the scene's E
  double tolerance_mm = 0.05;
  double sensitivity_step = 0.2;  // relative change of E for the sensitivity run; 0: none
  int max_runs = 4;
  int threads = -1;       // the runs' worker threads (-1: the scene's)
  bool quiet = false;
  std::string out_dir;    // created; locked while the calibration writes
};

struct CalibrationResult {
  double E_MPa = 0, deflection_mm = 0;
  bool converged = false;
  std::string calibration_json;  // OUT/calibration.json
};

// InputError for a bad request (named by the command's flags) before anything runs.
CalibrationResult calibrate_tissue_E(const CalibrationRequest& request);

}  // namespace needle
