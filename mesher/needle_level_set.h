#pragma once
// An OpenVDB narrow-band signed-distance level set of a closed triangle surface (the needle), for
// fast distance, inside/outside and normal queries: classifying tissue particles against the needle
// and measuring penetration.
//
// Accuracy: inside the band (|d| < half_width_voxels x voxel) the trilinear value differs from the exact
// point-to-triangle distance by a fraction of a voxel (tests bound it at 0.5 voxel; bench_mesh prints the
// measured error). Outside the band the value is clamped to +-band and the gradient is zero, but the sign
// stays right everywhere.
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "geometry/tri_surface.h"

namespace needle {

struct LevelSetOptions {
  double voxel_mm = 0.02;      // grid spacing; error scales with it, cost with its inverse square
  int half_width_voxels = 3;   // narrow band half width (outside, and inside unless interior_width_voxels is set)
  int interior_width_voxels = 0;  // band depth inside the surface; 0: half_width_voxels. Contact needs the
                                  // whole interior (depth >= the needle's radius) to push deep points out.
};

class NeedleLevelSet {
 public:
  // InputError for an open surface or absurd options.
  NeedleLevelSet(const TriSurface& surface, const LevelSetOptions& options = {});
  ~NeedleLevelSet();
  NeedleLevelSet(NeedleLevelSet&&) noexcept;
  NeedleLevelSet& operator=(NeedleLevelSet&&) noexcept;

  // Signed distance, negative inside, clamped to band_mm() outside and -interior_band_mm() inside.
  double signed_distance_mm(const Eigen::Vector3d& p) const;
  // Gradient of the distance (about the outward unit normal in the band, zero outside it).
  Eigen::Vector3d gradient(const Eigen::Vector3d& p) const;
  bool inside(const Eigen::Vector3d& p) const { return signed_distance_mm(p) < 0; }

  double band_mm() const;
  double interior_band_mm() const;
  double voxel_mm() const;
  long active_voxels() const;
  long memory_bytes() const;
  double build_seconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Points inside the needle when the needle is moved by `needle_offset_mm`.
struct PenetrationReport {
  Eigen::VectorXd signed_distance_mm;  // per point, as signed_distance_mm() returns it
  std::vector<int> inside;        // indices of points inside the needle
  double max_depth_mm = 0;        // deepest point below the needle surface, at most the band width
  bool depth_saturated = false;   // some point lies deeper than the band: max_depth_mm is a lower bound
};
PenetrationReport find_penetrations(const NeedleLevelSet& needle, const Eigen::MatrixX3d& points,
                                    const Eigen::Vector3d& needle_offset_mm = Eigen::Vector3d::Zero());

}  // namespace needle
