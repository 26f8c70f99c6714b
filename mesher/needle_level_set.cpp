#include "mesher/needle_level_set.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>

#include <chrono>
#include <cmath>
#include <fmt/format.h>

#include "core/input_error.h"
#include "geometry/surface_measures.h"

namespace needle {

struct NeedleLevelSet::Impl {
  openvdb::FloatGrid::Ptr grid;
  double voxel = 0, band = 0, interior_band = 0, seconds = 0;

  // Trilinear samples through one accessor. An unregistered ("unsafe") one: the grid does not change after it is
  // built, and a registered accessor costs a lock on the tree's registry to make and to drop, per query.
  class Sampler {
   public:
    explicit Sampler(const openvdb::FloatGrid& grid) : accessor_(grid.getConstUnsafeAccessor()), transform_(grid.transform()) {}
    // What GridSampler<accessor, BoxSampler>::wsSample computes (it takes registered accessors only).
    double operator()(const Eigen::Vector3d& p) const {
      float value = 0;
      openvdb::tools::BoxSampler::sample(accessor_, transform_.worldToIndex(openvdb::Vec3d(p.x(), p.y(), p.z())), value);
      return value;
    }

   private:
    openvdb::FloatGrid::ConstUnsafeAccessor accessor_;
    const openvdb::math::Transform& transform_;
  };
};

NeedleLevelSet::NeedleLevelSet(const TriSurface& surface, const LevelSetOptions& options) : impl_(std::make_unique<Impl>()) {
  NEEDLE_REQUIRE(std::isfinite(options.voxel_mm) && options.voxel_mm >= 1e-4 && options.voxel_mm <= 1.0,
                 fmt::format("level-set voxel size must be in [0.0001, 1] mm (got {})", options.voxel_mm));
  NEEDLE_REQUIRE(options.half_width_voxels >= 1 && options.half_width_voxels <= 64,
                 "level-set half width must be 1 to 64 voxels");
  NEEDLE_REQUIRE(options.interior_width_voxels >= 0 && options.interior_width_voxels <= 1000,
                 "level-set interior width must be 0 to 1000 voxels");
  const int interior_voxels = options.interior_width_voxels > 0 ? options.interior_width_voxels : options.half_width_voxels;
  const TopologyCheck topology = check_topology(surface);
  NEEDLE_REQUIRE(topology.closed_manifold(), "no level set of an open surface: " + topology.describe());
  const Eigen::Vector3d extent = surface.V.colwise().maxCoeff() - surface.V.colwise().minCoeff();
  const double area_voxels = 2 * (extent.x() * extent.y() + extent.y() * extent.z() + extent.z() * extent.x()) /
                             (options.voxel_mm * options.voxel_mm) * 2 * options.half_width_voxels;
  NEEDLE_REQUIRE(area_voxels < 1e9, fmt::format("level-set voxel {} mm is too small for this surface (about {:.2g} voxels)",
                                                options.voxel_mm, area_voxels));
  const auto start = std::chrono::steady_clock::now();
  openvdb::initialize();
  std::vector<openvdb::Vec3s> points(static_cast<size_t>(surface.num_vertices()));
  for (int i = 0; i < surface.num_vertices(); ++i)
    points[static_cast<size_t>(i)] = openvdb::Vec3s(static_cast<float>(surface.V(i, 0)), static_cast<float>(surface.V(i, 1)),
                                                    static_cast<float>(surface.V(i, 2)));
  std::vector<openvdb::Vec3I> triangles(static_cast<size_t>(surface.num_faces()));
  for (int f = 0; f < surface.num_faces(); ++f)
    triangles[static_cast<size_t>(f)] = openvdb::Vec3I(static_cast<unsigned>(surface.F(f, 0)), static_cast<unsigned>(surface.F(f, 1)),
                                                       static_cast<unsigned>(surface.F(f, 2)));
  const auto transform = openvdb::math::Transform::createLinearTransform(options.voxel_mm);
  const std::vector<openvdb::Vec4I> no_quads;
  impl_->grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
      *transform, points, triangles, no_quads, static_cast<float>(options.half_width_voxels), static_cast<float>(interior_voxels));
  impl_->voxel = options.voxel_mm;
  impl_->band = options.voxel_mm * options.half_width_voxels;
  impl_->interior_band = options.voxel_mm * interior_voxels;
  impl_->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

NeedleLevelSet::~NeedleLevelSet() = default;
NeedleLevelSet::NeedleLevelSet(NeedleLevelSet&&) noexcept = default;
NeedleLevelSet& NeedleLevelSet::operator=(NeedleLevelSet&&) noexcept = default;

double NeedleLevelSet::signed_distance_mm(const Eigen::Vector3d& p) const { return Impl::Sampler(*impl_->grid)(p); }

Eigen::Vector3d NeedleLevelSet::gradient(const Eigen::Vector3d& p) const {
  const Impl::Sampler sample(*impl_->grid);
  Eigen::Vector3d g;
  const double h = impl_->voxel;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(k) * h;
    g[k] = (sample(p + e) - sample(p - e)) / (2 * h);
  }
  return g;
}

double NeedleLevelSet::band_mm() const { return impl_->band; }
double NeedleLevelSet::interior_band_mm() const { return impl_->interior_band; }
double NeedleLevelSet::voxel_mm() const { return impl_->voxel; }
long NeedleLevelSet::active_voxels() const { return static_cast<long>(impl_->grid->activeVoxelCount()); }
long NeedleLevelSet::memory_bytes() const { return static_cast<long>(impl_->grid->memUsage()); }
double NeedleLevelSet::build_seconds() const { return impl_->seconds; }

PenetrationReport find_penetrations(const NeedleLevelSet& needle, const Eigen::MatrixX3d& points,
                                    const Eigen::Vector3d& needle_offset_mm) {
  PenetrationReport report;
  report.signed_distance_mm.resize(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const double d = needle.signed_distance_mm(points.row(i).transpose() - needle_offset_mm);
    report.signed_distance_mm[i] = d;
    if (d < 0) {
      report.inside.push_back(static_cast<int>(i));
      report.max_depth_mm = std::max(report.max_depth_mm, -d);
      if (-d >= 0.999 * needle.interior_band_mm()) report.depth_saturated = true;
    }
  }
  return report;
}

}  // namespace needle
