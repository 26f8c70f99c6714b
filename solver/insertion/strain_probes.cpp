#include "solver/insertion/strain_probes.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/input_error.h"
#include "solver/insertion/groove_fill.h"

namespace needle {

namespace {

bool is_top_facet(const std::string& tag) { return tag == "top" || tag.rfind("lancet", 0) == 0; }
bool is_groove_surface(const std::string& tag) { return tag == "groove_floor" || tag == "groove_wall"; }

// The q-quantile of the values by linear interpolation between order statistics.
double quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  const double position = q * static_cast<double>(values.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(below + 1, values.size() - 1);
  return values[below] + (position - static_cast<double>(below)) * (values[above] - values[below]);
}

StrainRegion summarise(const std::vector<double>& values) {
  StrainRegion r;
  r.particles = static_cast<int>(values.size());
  if (values.empty()) {
    r.median = r.p05 = r.min = std::numeric_limits<double>::quiet_NaN();
    return r;
  }
  r.median = quantile(values, 0.5);
  r.p05 = quantile(values, 0.05);
  r.min = *std::min_element(values.begin(), values.end());
  return r;
}

}  // namespace

double min_principal_log_strain(const Eigen::Matrix3d& b) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(b, Eigen::EigenvaluesOnly);
  const double smallest = eigen.eigenvalues().minCoeff();  // ascending, but take no chances
  return smallest > 0 ? 0.5 * std::log(smallest) : -std::numeric_limits<double>::infinity();
}

StrainProbes probe_strains(const StrainProbeInput& in) {
  const size_t n = in.reference_points.size();
  NEEDLE_REQUIRE(in.spacing_mm.size() == n && in.min_principal_strain.size() == n && in.contact_tag.size() == n,
                 "strain probes: one spacing, strain and contact tag per particle");
  NEEDLE_REQUIRE(in.tip_window_mm > 0, "strain probes: the window behind the tip point must be positive");
  std::vector<double> top, below, groove;
  const Eigen::Vector3d& A = in.tip_point;
  const double R = in.radius_mm;
  double groove_lo = 0, groove_hi = 0;
  if (in.groove) {
    groove_lo = std::max(in.groove->back_x_mm, in.tissue_min_x_mm);
    groove_hi = std::min(in.groove->front_x_mm, in.tissue_max_x_mm);
  }
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& X = in.reference_points[i];
    const double strain = in.min_principal_strain[i];
    if (!X.allFinite() || !std::isfinite(strain)) continue;
    const int tag = in.contact_tag[i];
    if (tag >= 0) {
      NEEDLE_REQUIRE(static_cast<size_t>(tag) < in.tag_names.size(), "strain probes: a contact tag outside the surface's tags");
      const std::string& name = in.tag_names[static_cast<size_t>(tag)];
      if (is_top_facet(name))
        top.push_back(strain);
      else if (!is_groove_surface(name) && X.x() <= A.x() && X.x() >= A.x() - in.tip_window_mm && X.y() <= A.y())
        below.push_back(strain);
    }
    // The groove's section, as the groove fill takes it (groove_fill.h), over its length in the tissue.
    if (in.groove && X.x() >= groove_lo && X.x() <= groove_hi && in_groove_section(*in.groove, R, X, in.spacing_mm[i])) groove.push_back(strain);
  }
  return {summarise(top), summarise(below), summarise(groove)};
}

}  // namespace needle
