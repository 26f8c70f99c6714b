#pragma once
// Exact distance from a point to a triangle surface by brute force over every triangle: the
// reference the OpenVDB level set is measured against (tests, bench_mesh). O(#F) per query.
#include <Eigen/Dense>

#include "geometry/tri_surface.h"

namespace needle {

// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

// Unsigned distance from p to the nearest triangle of the surface.
double distance_to_surface_mm(const TriSurface& surface, const Eigen::Vector3d& p);

}  // namespace needle
