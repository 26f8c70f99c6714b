#pragma once
// The hard-case suite's report (`needle stress`): each case of a suite run at a corner of the parameter space, with
// how it ended (finished, with its worst energy error and deepest penetration; or stopped, with the monitor that
// fired; never NaN, never a hang), as stress.md (a Markdown table) beside the sweep's own sweep.csv.
#include <filesystem>
#include <string>
#include <vector>

#include "sweeps/design_case.h"

namespace needle {

// What a case's outcome says against the suite's rule: empty where it holds, else why not (failed, timed out, a
// number that is not finite, a case not run).
std::string stress_finding(const CaseResult& result);

// stress.md, written whole or not at all; returns the number of findings.
int write_stress_report(const std::filesystem::path& dir, const std::string& suite_file, const std::vector<CaseResult>& rows);

}  // namespace needle
