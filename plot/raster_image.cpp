#include "plot/raster_image.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace needle {

void RgbImage::set(int x, int y, const Rgb& c) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  std::copy(c.begin(), c.end(), rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * width + x));
}

void RgbImage::blend(int x, int y, const Rgb& c, double alpha) {
  if (x < 0 || y < 0 || x >= width || y >= height || alpha <= 0) return;
  alpha = std::min(alpha, 1.0);
  for (int k = 0; k < 3; ++k) {
    unsigned char& p = rgb[static_cast<size_t>(3 * (static_cast<std::ptrdiff_t>(y) * width + x) + k)];
    p = static_cast<unsigned char>(std::lround(p * (1 - alpha) + c[static_cast<size_t>(k)] * alpha));
  }
}

void RgbImage::paste(const RgbImage& src, int x, int y) {
  for (int j = 0; j < src.height; ++j)
    for (int i = 0; i < src.width; ++i) {
      const size_t k = static_cast<size_t>(3 * (j * src.width + i));
      set(x + i, y + j, {src.rgb[k], src.rgb[k + 1], src.rgb[k + 2]});
    }
}

void RgbImage::fill_rect(int x0, int y0, int x1, int y1, const Rgb& c) {
  for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(width, x1); ++x) set(x, y, c);
}

void RgbImage::line(double x0, double y0, double x1, double y1, const Rgb& c, double width_px, double dash_px) {
  // Distance-to-segment coverage over the bounding box; cheap enough for plots.
  const double half = 0.5 * width_px;
  const int bx0 = std::max(0, static_cast<int>(std::floor(std::min(x0, x1) - half - 1)));
  const int bx1 = std::min(width - 1, static_cast<int>(std::ceil(std::max(x0, x1) + half + 1)));
  const int by0 = std::max(0, static_cast<int>(std::floor(std::min(y0, y1) - half - 1)));
  const int by1 = std::min(height - 1, static_cast<int>(std::ceil(std::max(y0, y1) + half + 1)));
  const double dx = x1 - x0, dy = y1 - y0, length_sq = dx * dx + dy * dy;
  for (int y = by0; y <= by1; ++y)
    for (int x = bx0; x <= bx1; ++x) {
      const double px = x + 0.5 - x0, py = y + 0.5 - y0;
      const double t = length_sq > 0 ? std::clamp((px * dx + py * dy) / length_sq, 0.0, 1.0) : 0.0;
      if (dash_px > 0 && std::fmod(t * std::sqrt(length_sq), 2 * dash_px) > dash_px) continue;
      const double distance = std::hypot(px - t * dx, py - t * dy);
      blend(x, y, c, std::clamp(half + 0.5 - distance, 0.0, 1.0));
    }
}

struct TextWriter::Impl {
  FT_Library library = nullptr;
  FT_Face face = nullptr;
};

TextWriter::TextWriter(int pixel_size) : impl_(std::make_unique<Impl>()) {
  if (FT_Init_FreeType(&impl_->library)) return;
  for (const char* font : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/TTF/DejaVuSans.ttf"})
    if (!FT_New_Face(impl_->library, font, 0, &impl_->face)) break;
  if (impl_->face) FT_Set_Pixel_Sizes(impl_->face, 0, static_cast<FT_UInt>(pixel_size));
}

TextWriter::~TextWriter() {
  if (impl_->face) FT_Done_Face(impl_->face);
  if (impl_->library) FT_Done_FreeType(impl_->library);
}

int TextWriter::width(const std::string& text) {
  if (!impl_->face) return 0;
  int w = 0;
  for (char c : text)
    if (!FT_Load_Char(impl_->face, static_cast<unsigned char>(c), FT_LOAD_DEFAULT)) w += static_cast<int>(impl_->face->glyph->advance.x >> 6);
  return w;
}

void TextWriter::draw(RgbImage& image, int x, int baseline, const std::string& text, const Rgb& color) {
  if (!impl_->face) return;
  for (char c : text) {
    if (FT_Load_Char(impl_->face, static_cast<unsigned char>(c), FT_LOAD_RENDER)) continue;
    const FT_GlyphSlot g = impl_->face->glyph;
    for (unsigned row = 0; row < g->bitmap.rows; ++row)
      for (unsigned col = 0; col < g->bitmap.width; ++col) {
        const double alpha = g->bitmap.buffer[row * static_cast<unsigned>(g->bitmap.pitch) + col] / 255.0;
        if (alpha > 0) image.blend(x + g->bitmap_left + static_cast<int>(col), baseline - g->bitmap_top + static_cast<int>(row), color, alpha);
      }
    x += static_cast<int>(g->advance.x >> 6);
  }
}

void TextWriter::draw_vertical(RgbImage& image, int x, int bottom, const std::string& text, const Rgb& color) {
  // Render horizontally into a scratch image, then copy it rotated by 90 degrees counter-clockwise.
  const int w = width(text) + 4, h = 2 * (impl_->face ? static_cast<int>(impl_->face->size->metrics.y_ppem) : 0) + 4;
  if (w <= 4 || h <= 4) return;
  RgbImage scratch(w, h);
  draw(scratch, 2, h * 3 / 4, text, {0, 0, 0});
  for (int sy = 0; sy < h; ++sy)
    for (int sx = 0; sx < w; ++sx) {
      const double alpha = 1.0 - scratch.rgb[static_cast<size_t>(3 * (sy * w + sx))] / 255.0;
      image.blend(x - h * 3 / 4 + sy, bottom - sx, color, alpha);
    }
}

void write_png(const RgbImage& image, const std::string& path) {
  FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) throw std::runtime_error("cannot open '" + path + "' for writing");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    throw std::runtime_error("libpng failed writing '" + path + "'");
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(image.rgb.data() + static_cast<size_t>(3 * y * image.width)));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(file);
}

}  // namespace needle
