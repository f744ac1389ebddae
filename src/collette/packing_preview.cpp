#include "uh/collette/packing_preview.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>
#include <limits>
#include <string>

#include "uh/core/atomic_file_writer.hpp"

namespace uh::collette {
namespace {

struct Rgb {
  double r, g, b;
};

// small perceptual ramp (viridis-like): dark blue for small radii to yellow for large ones
Rgb ramp(double t) {
  static constexpr Rgb kStops[5] = {{0.27, 0.00, 0.33}, {0.23, 0.32, 0.55}, {0.13, 0.57, 0.55}, {0.37, 0.79, 0.38}, {0.99, 0.91, 0.14}};
  t = std::clamp(t, 0.0, 1.0) * 4.0;
  const int i = std::min(3, static_cast<int>(t));
  const double f = t - i;
  const Rgb& a = kStops[i];
  const Rgb& b = kStops[i + 1];
  return {a.r + (b.r - a.r) * f, a.g + (b.g - a.g) * f, a.b + (b.b - a.b) * f};
}

// libpng's output callback: append to the std::string behind png_get_io_ptr
void append_png_bytes(png_structp png, png_bytep data, png_size_t size) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  try {
    out->append(reinterpret_cast<const char*>(data), size);
  } catch (...) {
    png_error(png, "out of memory");  // longjmps; an exception must not cross libpng's C frames
  }
}

// the PNG bytes of an RGB picture; an empty string if libpng fails
std::string encode_png(int w, int h, const std::vector<unsigned char>& rgb) {
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return {};
  }
  // libpng reports errors by longjmp; nothing with a destructor starts living between here and the end
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    out.clear();
    return out;
  }
  png_set_write_fn(png, &out, append_png_bytes, nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < h; ++y) {
    png_write_row(png, rgb.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w) * 3);
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

// The view: `back` points from the scene towards the camera; `right` and `up` span the picture.
struct Camera {
  Vec3 back{}, right{}, up{}, light{};
};

Camera camera_of(const PreviewOptions& options) {
  Camera c;
  const double az = options.view_azimuth_deg * kPi / 180.0;
  const double el = options.view_elevation_deg * kPi / 180.0;
  c.back = {std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
  c.right = normalized(cross(Vec3{0.0, 1.0, 0.0}, c.back));
  c.up = cross(c.back, c.right);
  c.light = normalized(c.back * 0.8 + c.up * 0.6 - c.right * 0.4);
  return c;
}

// Where the spheres lie on the picture plane, their radii, and the depth of the section's cut
// (through the middle of their centres).
struct Extent {
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  double rmin = 1e300, rmax = 0.0;
  double cut = 0.0;
};

Extent extent_of(const std::vector<Sphere>& spheres, const Camera& cam) {
  Extent e;
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const Sphere& s : spheres) {
    const Vec3 c{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
    const double r = static_cast<double>(s.radius);
    e.xmin = std::min(e.xmin, dot(c, cam.right) - r);
    e.xmax = std::max(e.xmax, dot(c, cam.right) + r);
    e.ymin = std::min(e.ymin, dot(c, cam.up) - r);
    e.ymax = std::max(e.ymax, dot(c, cam.up) + r);
    e.rmin = std::min(e.rmin, r);
    e.rmax = std::max(e.rmax, r);
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
  }
  e.cut = spheres.empty() ? 0.0 : dot((lo + hi) * 0.5, cam.back);
  return e;
}

// An RGB picture with a depth buffer, and how the scene maps onto it.
struct Canvas {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
  std::vector<double> depth;
  double scale = 0.0;  // pixels per length unit
  double cx = 0.0, cy = 0.0;
  double log_span = 0.0;
};

void put_pixel(Canvas& canvas, std::size_t pix, const Rgb& base, double shade) {
  const Rgb col{base.r * shade, base.g * shade, base.b * shade};
  canvas.rgb[pix * 3 + 0] = static_cast<unsigned char>(std::clamp(col.r * 255.0, 0.0, 255.0));
  canvas.rgb[pix * 3 + 1] = static_cast<unsigned char>(std::clamp(col.g * 255.0, 0.0, 255.0));
  canvas.rgb[pix * 3 + 2] = static_cast<unsigned char>(std::clamp(col.b * 255.0, 0.0, 255.0));
}

// Ray-casts one sphere into the canvas, nearest surface wins; with a section, the half nearer the
// camera than the cut is removed and what it cuts is drawn as flat discs.
void draw_sphere(Canvas& canvas, const Sphere& s, const Camera& cam, const Extent& e, const PreviewOptions& options) {
  const Vec3 c{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
  const double r = static_cast<double>(s.radius);
  const double cd = dot(c, cam.back);
  if (options.section && cd - r > e.cut) return;  // wholly in the removed half
  const double scale = canvas.scale;
  const double px = 0.5 * canvas.w + (dot(c, cam.right) - canvas.cx) * scale;
  const double py = 0.5 * canvas.h - (dot(c, cam.up) - canvas.cy) * scale;
  const double pr = r * scale;
  const Rgb base = ramp(std::log(r / e.rmin) / canvas.log_span);
  const int x0 = std::max(0, static_cast<int>(std::floor(px - pr)));
  const int x1 = std::min(canvas.w - 1, static_cast<int>(std::ceil(px + pr)));
  const int y0 = std::max(0, static_cast<int>(std::floor(py - pr)));
  const int y1 = std::min(canvas.h - 1, static_cast<int>(std::ceil(py + pr)));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double dx = (x + 0.5 - px) / scale;
      const double dy = -(y + 0.5 - py) / scale;
      const double q = r * r - dx * dx - dy * dy;
      if (q < 0.0) continue;
      const double dz = std::sqrt(q);
      double z = cd + dz;
      Vec3 n{dx / r, dy / r, dz / r};  // in (right, up, back) coordinates
      bool flat = false;
      if (options.section && z > e.cut) {
        if (cd - dz > e.cut) continue;  // the whole chord lies in the removed half
        z = e.cut;
        flat = true;
      }
      const auto pix = static_cast<std::size_t>(y) * static_cast<std::size_t>(canvas.w) + static_cast<std::size_t>(x);
      if (z <= canvas.depth[pix]) continue;
      canvas.depth[pix] = z;
      // cross-sections: flat and bright, so the cut reads as a plane of discs
      const double shade =
          flat ? 0.95 : 0.25 + 0.75 * std::max(0.0, dot(cam.right * n.x + cam.up * n.y + cam.back * n.z, cam.light));
      put_pixel(canvas, pix, base, shade);
    }
  }
}

}  // namespace

Status write_packing_preview(const std::vector<Sphere>& spheres, const std::filesystem::path& png,
                             const PreviewOptions& options) {
  const int w = options.width;
  const int h = options.height;
  if (w < 1 || h < 1 || w > 16384 || h > 16384) {
    return Error{fmt::format("{}: preview size {}x{} is out of range (1..16384 pixels a side)", png.string(), w, h)};
  }
  const Camera cam = camera_of(options);
  const Extent e = extent_of(spheres, cam);
  Canvas canvas;
  canvas.w = w;
  canvas.h = h;
  canvas.rgb.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3, 245);
  if (!spheres.empty()) {
    canvas.depth.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), -std::numeric_limits<double>::infinity());
    const double span = std::max(e.xmax - e.xmin, e.ymax - e.ymin);
    canvas.scale = 0.92 * std::min(w, h) / std::max(span, 1e-30);
    canvas.cx = 0.5 * (e.xmin + e.xmax);
    canvas.cy = 0.5 * (e.ymin + e.ymax);
    canvas.log_span = std::log(std::max(e.rmax / e.rmin, 1.0 + 1e-9));
    for (const Sphere& s : spheres) draw_sphere(canvas, s, cam, e, options);
  }

  const std::string bytes = encode_png(w, h, canvas.rgb);
  if (bytes.empty()) return Error{fmt::format("{}: libpng could not encode the picture", png.string())};
  return write_file_atomically(png, bytes);
}

}  // namespace uh::collette
