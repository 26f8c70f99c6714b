#include "geometry/render_png.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <limits>
#include <vector>

#include "core/input_error.h"
#include "geometry/mesh_io.h"
#include "geometry/tag_colors.h"
#include "plot/raster_image.h"

namespace needle {
namespace {

// Orthographic view along -eye, the needle axis kept horizontal on screen.
void draw_panel(const TriSurface& s, const RenderOptions& options, const Eigen::Vector3d& eye_dir, RgbImage& image,
                int x0, int y0, int w, int h) {
  const Eigen::Vector3d eye = eye_dir.normalized();
  Eigen::Vector3d right = Eigen::Vector3d::UnitX() - eye.x() * eye;
  right.normalize();
  const Eigen::Vector3d up = eye.cross(right);
  std::vector<int> faces;
  double min_u = 1e300, max_u = -1e300, min_v = 1e300, max_v = -1e300;
  for (int f = 0; f < s.num_faces(); ++f) {
    bool keep = false;
    for (int k = 0; k < 3; ++k) keep = keep || s.V(s.F(f, k), 0) >= options.view_from_x_mm;
    if (!keep) continue;
    faces.push_back(f);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = s.V.row(s.F(f, k));
      if (p.x() < options.view_from_x_mm) continue;
      min_u = std::min(min_u, p.dot(right)), max_u = std::max(max_u, p.dot(right));
      min_v = std::min(min_v, p.dot(up)), max_v = std::max(max_v, p.dot(up));
    }
  }
  if (faces.empty()) return;
  const double scale = 0.92 * std::min(w / (max_u - min_u), h / (max_v - min_v));
  const double cu = 0.5 * (min_u + max_u), cv = 0.5 * (min_v + max_v);
  std::vector<double> depth(static_cast<size_t>(w) * h, -std::numeric_limits<double>::infinity());
  const Eigen::Vector3d light = (eye + 0.4 * up).normalized();
  for (int f : faces) {
    Eigen::Vector3d p[3];
    double sx[3], sy[3], sz[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = s.V.row(s.F(f, k));
      sx[k] = 0.5 * w + (p[k].dot(right) - cu) * scale;
      sy[k] = 0.5 * h - (p[k].dot(up) - cv) * scale;
      sz[k] = p[k].dot(eye);
    }
    Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
    if (n.norm() == 0 || n.dot(eye) <= 0) continue;  // back face
    n.normalize();
    const double shade = 0.55 + 0.45 * std::abs(n.dot(light));
    std::array<unsigned char, 3> color = tag_color(s.face_tag.size() ? s.tag_names[s.face_tag(f)] : "shaft");
    for (auto& c : color) c = static_cast<unsigned char>(std::min(255.0, c * shade));
    const int bx0 = std::max(0, static_cast<int>(std::floor(std::min({sx[0], sx[1], sx[2]}))));
    const int bx1 = std::min(w - 1, static_cast<int>(std::ceil(std::max({sx[0], sx[1], sx[2]}))));
    const int by0 = std::max(0, static_cast<int>(std::floor(std::min({sy[0], sy[1], sy[2]}))));
    const int by1 = std::min(h - 1, static_cast<int>(std::ceil(std::max({sy[0], sy[1], sy[2]}))));
    const double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
    if (std::abs(area) < 1e-12) continue;
    for (int y = by0; y <= by1; ++y)
      for (int x = bx0; x <= bx1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double w0 = ((sx[1] - px) * (sy[2] - py) - (sx[2] - px) * (sy[1] - py)) / area;
        const double w1 = ((sx[2] - px) * (sy[0] - py) - (sx[0] - px) * (sy[2] - py)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double z = w0 * sz[0] + w1 * sz[1] + w2 * sz[2];
        const double x_world = w0 * p[0].x() + w1 * p[1].x() + w2 * p[2].x();
        if (x_world < options.view_from_x_mm) continue;
        double& d = depth[static_cast<size_t>(y) * w + x];
        if (z <= d) continue;
        d = z;
        image.set(x0 + x, y0 + y, color);
      }
  }
}

}  // namespace

RgbImage render_tip_image(const TriSurface& s, const RenderOptions& options) {
  const int w = options.panel_width_px, h = options.panel_height_px, header = 40, legend = 60;
  RgbImage image(w, 2 * h + header + legend);
  TextWriter text(18), small(15);
  const std::array<unsigned char, 3> ink = {30, 30, 30};
  text.draw(image, 12, 27, options.title, ink);
  draw_panel(s, options, Eigen::Vector3d(0.45, 0.75, 0.55), image, 0, header, w, h);
  small.draw(image, 12, header + 20, "from above (+y, groove side)", ink);
  draw_panel(s, options, Eigen::Vector3d(0.45, -0.75, 0.55), image, 0, header + h, w, h);
  small.draw(image, 12, header + h + 20, "from below (-y)", ink);
  // Legend: the tags that have triangles, wrapped to the image width.
  std::vector<bool> present(s.tag_names.size(), false);
  for (int f = 0; f < s.num_faces(); ++f) present[s.face_tag.size() ? s.face_tag(f) : 0] = true;
  int x = 12, y = header + 2 * h + 6;
  for (size_t t = 0; t < s.tag_names.size(); ++t) {
    if (!present[t]) continue;
    const std::string& name = s.tag_names[t];
    const int item_width = 26 + 9 * static_cast<int>(name.size()) + 14;
    if (x + item_width > w) x = 12, y += 26;
    const auto color = tag_color(name);
    for (int dy = 0; dy < 16; ++dy)
      for (int dx = 0; dx < 16; ++dx) image.set(x + dx, y + dy, color);
    small.draw(image, x + 21, y + 14, name, ink);
    x += item_width;
  }
  return image;
}

void render_tip_png(const TriSurface& s, const std::string& path, const RenderOptions& options) {
  const RgbImage image = render_tip_image(s, options);
  write_file_atomically(path, [&](const std::string& scratch_path) { write_png(image, scratch_path); });
}

}  // namespace needle
