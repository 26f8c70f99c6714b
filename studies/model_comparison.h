#pragma once
// Other models beside this one in the paper's report (`needle paper --compare LABEL=FILE`): each is
// another report's results.json, the same needles under another model (particle spacing, the needle's
// cut, E). The report gets a table of delta and delta / delta_SB (which does not depend on E to first
// order), the targets each model meets, whether the models' spread covers the experiment, the groove
// fill of each, and models.png.
#include <string>
#include <utility>
#include <vector>

#include "studies/paper_results.h"
#include "plot/raster_image.h"

namespace needle {

struct ComparedModel {
  std::string label, results_path;
};

// "LABEL=FILE" -> its parts; InputError naming the flag for a missing label or file name.
ComparedModel parse_compared_model(const std::string& text, const char* flag = "--compare");

// A model's report: this one's runs, or another's read back from its results.json.
struct ModelResults {
  std::string label, path, tissue;
  double tissue_E_MPa = kNaN;
  std::vector<NeedleOutcome> needles;
};

// InputError if the file cannot be read or holds no needles.
ModelResults read_model_results(const ComparedModel& model);

// The lowest and highest delta / delta_SB of the needle over the models that ran it and SB (the ratio does not
// depend on E to first order); {NaN, NaN} where none did.
std::pair<double, double> ratio_to_sb_span(const std::vector<ModelResults>& models, const std::string& needle);

// delta of each model, the experiment and LS-DYNA, per needle.
RgbImage model_bars(const std::vector<ModelResults>& models, const std::vector<std::string>& needles,
                    const std::vector<PaperReferenceNeedle>& reference);

// The report's section "The same needles under other models" (Markdown, ending with models.png).
std::string models_section(const std::vector<ModelResults>& models, const std::vector<std::string>& needles,
                           const std::vector<PaperReferenceNeedle>& reference);

}  // namespace needle
