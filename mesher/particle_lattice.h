#pragma once
// Tissue particle sets for the SPG solver: a lattice filling a box, each particle with the volume of
// its dual cell and boundary flags from the box face it lies on.
//
// The lattice is a tensor product: along each axis the box is split into equal intervals of about
// spacing_mm (the count is rounded, the effective spacing reported), and an optional region of
// interest is split `refinement` times finer (through the whole box, or nested: LatticeGrading). Particles sit on the lattice nodes, so the faces
// (fixed faces, the symmetry plane) carry particles, as the nodes of a hexahedral mesh would.
// A particle's volume is the product of its half-interval lengths; the volumes sum to the box
// volume exactly.
#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace needle {

enum class FaceCondition { free, fixed, symmetry };

// Particle flags (bits): a particle on two faces carries both faces' flags. kParticleOpenSymmetry is set
// during a run (solver/separation/symmetry_slit.h): a symmetry particle a crack in the plane has released keeps
// z >= 0 only, its mirror image being its contact partner. kParticleCrushed is set during a run too
// (solver/separation/lip_release.h): the material there has lost its shear stiffness and keeps only its pressure.
enum ParticleFlag : std::uint8_t {
  kParticleFixed = 1,
  kParticleSymmetry = 2,
  kParticleFreeSurface = 4,
  kParticleOpenSymmetry = 8,
  kParticleCrushed = 16
};

struct TissueBox {
  Eigen::Vector3d min_mm{0.0, -4.0, 0.0};  // the paper's 40 x 8 x 2 mm half block, needle path y = z = 0
  Eigen::Vector3d max_mm{40.0, 4.0, 2.0};
  // Faces in the order x_min, x_max, y_min, y_max, z_min, z_max. Paper: entry and back faces free,
  // y = +-4 and z = 2 fixed, z = 0 symmetry.
  std::array<FaceCondition, 6> faces{FaceCondition::free,  FaceCondition::free,     FaceCondition::fixed,
                                     FaceCondition::fixed, FaceCondition::symmetry, FaceCondition::fixed};
};

// How the region of interest is refined:
//  - tensor: each axis's intervals within the region's range are split, through the whole box (the fine x
//    intervals of a region spanning the block's length reach every particle of the block);
//  - nested: the region alone holds the fine lattice; outside it the coarse lattice stays coarse along every
//    axis. The coarse nodes on the region's closed box are the fine ones there; the fine dual cells on a face of
//    the region inside the box reach half a coarse interval out, so that the volumes still sum to the box's.
enum class LatticeGrading { tensor, nested };

LatticeGrading lattice_grading_from_name(const std::string& name);  // "tensor", "nested"; InputError otherwise
std::string lattice_grading_name(LatticeGrading grading);

struct RegionOfInterest {
  Eigen::Vector3d min_mm, max_mm;  // snapped outward to the coarse lattice
  int refinement = 2;              // fine spacing = spacing / refinement
  LatticeGrading grading = LatticeGrading::tensor;
};

struct LatticeOptions {
  double spacing_mm = 0.4;
  std::optional<RegionOfInterest> region_of_interest;
};

struct ParticleSet {
  Eigen::MatrixX3d x_mm;                                // #P by 3 positions
  Eigen::VectorXd volume_mm3;                           // #P dual-cell volumes
  Eigen::VectorXd spacing_mm;                           // #P largest neighbouring interval (sets a spherical support)
  Eigen::MatrixX3d axis_spacing_mm;                     // #P by 3: the largest neighbouring interval along each axis
                                                        // (sets an ellipsoidal support; may be empty for other sets)
  Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 1> flags;  // #P ParticleFlag bits
  Eigen::Vector3i nodes_per_axis{0, 0, 0};                // a tensor lattice's node counts (0 for a nested one)
  int num_particles() const { return static_cast<int>(x_mm.rows()); }
};

// InputError for an empty box, a spacing that is not positive or leaves fewer than one interval
// across an axis, a lattice over kMaxLatticeParticles, or a region of interest outside the box.
ParticleSet make_particle_lattice(const TissueBox& box, const LatticeOptions& options);

// The most particles a lattice may have, and the bound make_particle_lattice holds it to: a box of these extents at
// this spacing, refined this many times everywhere (an upper bound for a refined region). The scene reader checks the
// same bound, so a sweep's pre-run check refuses a spacing that no case could run.
inline constexpr double kMaxLatticeParticles = 5e7;
double lattice_particle_bound(const Eigen::Vector3d& extent_mm, double spacing_mm, int refinement);

// Names as used in scene files and reports.
FaceCondition face_condition_from_name(const std::string& name);
std::string face_condition_name(FaceCondition condition);

}  // namespace needle
