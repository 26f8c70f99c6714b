#include "solver/tissue/hencky_strain.h"

#include <array>
#include <cmath>

namespace needle {
namespace {

// A symmetric 3x3 matrix by its six entries. The products below are of matrices that commute (all are functions
// of b), whose product is then symmetric: its upper triangle is all there is to compute.
struct Sym3 {
  double xx, yy, zz, xy, xz, yz;
};

inline Sym3 commuting_product(const Sym3& a, const Sym3& b) {
  return {a.xx * b.xx + a.xy * b.xy + a.xz * b.xz, a.xy * b.xy + a.yy * b.yy + a.yz * b.yz, a.xz * b.xz + a.yz * b.yz + a.zz * b.zz,
          a.xx * b.xy + a.xy * b.yy + a.xz * b.yz, a.xx * b.xz + a.xy * b.yz + a.xz * b.zz, a.xy * b.xz + a.yy * b.yz + a.yz * b.zz};
}

// 1 / (2k + 1): the series' coefficients, up to the most terms the limit needs.
constexpr int kMostTerms = 20;
constexpr std::array<double, kMostTerms> odd_reciprocals() {
  std::array<double, kMostTerms> c{};
  for (int k = 0; k < kMostTerms; ++k) c[static_cast<size_t>(k)] = 1.0 / (2 * k + 1);
  return c;
}
constexpr std::array<double, kMostTerms> kOddReciprocals = odd_reciprocals();

}  // namespace

bool hencky_strain_near_identity(const Eigen::Matrix3d& b, Eigen::Matrix3d& H) {
  // D = b - I (exact where b's diagonal lies within [0.5, 2]), and Y = D (2 I + D)^-1 through the adjugate.
  const Sym3 d{b(0, 0) - 1, b(1, 1) - 1, b(2, 2) - 1, b(1, 0), b(2, 0), b(2, 1)};
  const Sym3 m{d.xx + 2, d.yy + 2, d.zz + 2, d.xy, d.xz, d.yz};
  const Sym3 adj{m.yy * m.zz - m.yz * m.yz, m.xx * m.zz - m.xz * m.xz, m.xx * m.yy - m.xy * m.xy,
                 m.xz * m.yz - m.xy * m.zz, m.xy * m.yz - m.xz * m.yy, m.xy * m.xz - m.xx * m.yz};
  const double det = m.xx * adj.xx + m.xy * adj.xy + m.xz * adj.xz;
  if (!(det > 0)) return false;  // b + I of a positive definite b has det > 1; not finite fails here too
  const double inv_det = 1.0 / det;
  const Sym3 inverse{adj.xx * inv_det, adj.yy * inv_det, adj.zz * inv_det, adj.xy * inv_det, adj.xz * inv_det, adj.yz * inv_det};
  const Sym3 y = commuting_product(d, inverse);
  const double y2 = y.xx * y.xx + y.yy * y.yy + y.zz * y.zz + 2 * (y.xy * y.xy + y.xz * y.xz + y.yz * y.yz);  // |Y|_F^2
  if (!(y2 <= kHenckySeriesLimit * kHenckySeriesLimit)) return false;
  // 1/2 ln b = artanh Y = Y sum_k (Y^2)^k / (2k + 1). |Y|_F bounds Y's spectral radius y, each eigenvalue of H is at
  // least Y's (|artanh y| >= |y|), and after the terms up to k = K the remainder is at most
  // y^(2K+3) / ((2K+3) (1 - y^2)): K is the first for which that is below 1e-17 y.
  int K = 0;
  for (double power = y2; power > 1e-17 * (2 * K + 3) * (1 - y2) && K + 1 < kMostTerms; power *= y2) ++K;
  // Horner in Z = Y^2 from the highest term.
  const Sym3 z = commuting_product(y, y);
  double c = kOddReciprocals[static_cast<size_t>(K)];
  Sym3 s{c, c, c, 0, 0, 0};
  for (int k = K - 1; k >= 0; --k) {
    s = commuting_product(s, z);
    c = kOddReciprocals[static_cast<size_t>(k)];
    s.xx += c, s.yy += c, s.zz += c;
  }
  const Sym3 h = commuting_product(y, s);
  H << h.xx, h.xy, h.xz, h.xy, h.yy, h.yz, h.xz, h.yz, h.zz;
  return true;
}

}  // namespace needle
