#pragma once
// An RGB raster with anti-aliased text (FreeType, the DejaVu font Debian ships) and lines, written as
// PNG through libpng. Shared by the tip pictures and the plots.
#include <array>
#include <memory>
#include <string>
#include <vector>

namespace needle {

using Rgb = std::array<unsigned char, 3>;

struct RgbImage {
  int width, height;
  std::vector<unsigned char> rgb;  // row-major, 3 bytes per pixel
  RgbImage(int w, int h) : width(w), height(h), rgb(static_cast<size_t>(3 * w * h), 255) {}
  void set(int x, int y, const Rgb& c);
  void blend(int x, int y, const Rgb& c, double alpha);
  // Anti-aliased line of the given width in pixels; dash_px > 0 draws dashes of that length.
  void line(double x0, double y0, double x1, double y1, const Rgb& c, double width_px = 1.5, double dash_px = 0);
  void fill_rect(int x0, int y0, int x1, int y1, const Rgb& c);
  // Copies src with its top-left corner at (x, y), clipped to this image.
  void paste(const RgbImage& src, int x, int y);
};

// Draws text with its baseline at y; silently draws nothing if no font is installed.
class TextWriter {
 public:
  explicit TextWriter(int pixel_size);
  ~TextWriter();
  TextWriter(const TextWriter&) = delete;
  TextWriter& operator=(const TextWriter&) = delete;
  void draw(RgbImage& image, int x, int baseline, const std::string& text, const Rgb& color);
  int width(const std::string& text);  // advance in pixels
  // Text rotated by 90 degrees (reading upward), its baseline on the vertical line x.
  void draw_vertical(RgbImage& image, int x, int bottom, const std::string& text, const Rgb& color);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes the image as an 8-bit RGB PNG (callers make it atomic with write_file_atomically).
void write_png(const RgbImage& image, const std::string& path);

}  // namespace needle
