#include "session_plot.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "uh/core/atomic_file_writer.hpp"
#include "uh/core/math.hpp"

namespace uh::cli {
namespace {

struct Series {
  std::vector<double> t;
  std::vector<double> v;
};

struct Panel {
  std::string title;
  std::string unit;
  std::vector<Series> series;
  std::vector<std::array<double, 3>> colours;
  std::vector<std::string> labels;
  double target = -1.0;  // a dashed reference line (e.g. the target rate), < 0 for none
  std::string x_unit = "time [s]";
  double x_max = -1.0;  // the x axis' end; < 0: the plot's time span
};

// A "nice" step for about `count` grid lines over `range`.
double nice_step(double range, int count) {
  const double raw = range / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * power) return m * power;
  return 10.0 * power;
}

void draw_panel(cairo_t* cr, const Panel& p, double x0, double y0, double w, double h, double time_span) {
  const double t_max = p.x_max > 0.0 ? p.x_max : time_span;
  double v_max = p.target > 0 ? p.target * 1.1 : 0.0;
  for (const auto& s : p.series)
    for (double v : s.v) v_max = std::max(v_max, v);
  if (!(v_max > 0.0)) v_max = 1.0;
  v_max *= 1.05;
  const double left = x0 + 70, right = x0 + w - 20, top = y0 + 28, bottom = y0 + h - 30;
  const auto X = [&](double t) { return left + (right - left) * (t_max > 0 ? t / t_max : 0.0); };
  const auto Y = [&](double v) { return bottom - (bottom - top) * v / v_max; };

  cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 14);
  cairo_move_to(cr, left, y0 + 18);
  cairo_show_text(cr, p.title.c_str());

  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 11);
  cairo_set_line_width(cr, 1.0);
  const double vs = nice_step(v_max, 5);
  for (double v = 0; v <= v_max + 1e-12; v += vs) {
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_move_to(cr, left, Y(v));
    cairo_line_to(cr, right, Y(v));
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    const std::string label = fmt::format("{:g}", v);
    cairo_move_to(cr, left - 8 - 6.0 * static_cast<double>(label.size()), Y(v) + 4);
    cairo_show_text(cr, label.c_str());
  }
  const double ts = nice_step(std::max(t_max, 1e-3), 8);
  for (double t = 0; t <= t_max + 1e-12; t += ts) {
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    const std::string label = fmt::format("{:g}", t);
    cairo_move_to(cr, X(t) - 3.0 * static_cast<double>(label.size()), bottom + 16);
    cairo_show_text(cr, label.c_str());
  }
  cairo_move_to(cr, right - 6.0 * static_cast<double>(p.x_unit.size()), bottom + 28);
  cairo_show_text(cr, p.x_unit.c_str());
  cairo_save(cr);
  cairo_move_to(cr, x0 + 14, (top + bottom) / 2 + 20);
  cairo_rotate(cr, -kPi / 2);
  cairo_show_text(cr, p.unit.c_str());
  cairo_restore(cr);

  cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
  cairo_rectangle(cr, left, top, right - left, bottom - top);
  cairo_stroke(cr);

  if (p.target > 0) {
    const double dashes[] = {6.0, 4.0};
    cairo_set_dash(cr, dashes, 2, 0);
    cairo_set_source_rgb(cr, 0.5, 0.5, 0.5);
    cairo_move_to(cr, left, Y(p.target));
    cairo_line_to(cr, right, Y(p.target));
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
  }
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const Series& s = p.series[k];
    cairo_set_source_rgb(cr, p.colours[k][0], p.colours[k][1], p.colours[k][2]);
    cairo_set_line_width(cr, 1.2);
    for (std::size_t i = 0; i < s.t.size(); ++i) {
      if (i == 0) cairo_move_to(cr, X(s.t[i]), Y(s.v[i]));
      else cairo_line_to(cr, X(s.t[i]), Y(s.v[i]));
    }
    cairo_stroke(cr);
    cairo_move_to(cr, right - 300, top + 16 + 14.0 * static_cast<double>(k));
    cairo_show_text(cr, p.labels[k].c_str());
  }
}

// At most ~4000 points per series: the per-bucket maximum keeps every peak visible.
Series decimate(const std::vector<double>& t, const std::vector<double>& v) {
  Series out;
  const std::size_t n = t.size();
  const std::size_t bucket = std::max<std::size_t>(1, n / 4000);
  for (std::size_t i = 0; i < n; i += bucket) {
    double m = 0.0;
    const std::size_t end = std::min(n, i + bucket);
    for (std::size_t k = i; k < end; ++k) m = std::max(m, v[k]);
    out.t.push_back(t[i]);
    out.v.push_back(m);
  }
  return out;
}

// cairo's PNG output callback: append to the std::string behind `closure`
cairo_status_t append_png_bytes(void* closure, const unsigned char* data, unsigned int length) {
  try {
    static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  } catch (...) {
    return CAIRO_STATUS_NO_MEMORY;  // an exception must not cross cairo's C frames
  }
  return CAIRO_STATUS_SUCCESS;
}

// Draws the panels one under the other and writes the PNG atomically.
Status write_panels(const std::vector<Panel>& panels, double t_max, const std::filesystem::path& png) {
  constexpr int kWidth = 1200, kPanelHeight = 260;
  cairo_surface_t* surface =
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, kWidth, kPanelHeight * static_cast<int>(panels.size()));
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  for (std::size_t i = 0; i < panels.size(); ++i)
    draw_panel(cr, panels[i], 0, kPanelHeight * static_cast<double>(i), kWidth, kPanelHeight, t_max);
  cairo_destroy(cr);
  std::string bytes;
  const cairo_status_t status = cairo_surface_write_to_png_stream(surface, append_png_bytes, &bytes);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS) {
    return Error{fmt::format("{}: cannot write the plot: {}", png.string(), cairo_status_to_string(status))};
  }
  return write_file_atomically(png, bytes);
}

// A soft object's force against its indentation over its steps (at most ~4000 of them, evenly
// picked): pressing and releasing draw the object's force-indentation curve.
Panel indentation_panel(const controllers::SessionReport::SoftObjectReport& soft) {
  Series curve;
  double deepest = 0.0;
  const std::size_t stride = std::max<std::size_t>(1, soft.samples.size() / 4000);
  for (std::size_t i = 0; i < soft.samples.size(); i += stride) {
    curve.t.push_back(soft.samples[i].indentation_m * 1e3);
    curve.v.push_back(soft.samples[i].force_n);
    deepest = std::max(deepest, curve.t.back());
  }
  return Panel{.title = fmt::format("Soft object '{}': force against indentation (deepest {:.2f} mm)", soft.object, deepest),
               .unit = "|F| [N]", .series = {curve}, .colours = {{0.55, 0.25, 0.65}},
               .labels = {"a point per simulation step"},
               .x_unit = "indentation [mm]", .x_max = deepest > 0.0 ? deepest * 1.05 : 1.0};
}

}  // namespace

Status write_session_plot(const controllers::SessionReport& report, const std::filesystem::path& png) {
  std::vector<double> t, f, tq;
  for (const auto& s : report.timeline) {
    t.push_back(s.time_s);
    f.push_back(s.force_n);
    tq.push_back(s.torque_nm);
  }
  double t_max = report.seconds;
  for (double x : t) t_max = std::max(t_max, x);

  Panel force{.title = fmt::format("Force sent to the device ({}, {} Hz haptic)", report.scene, report.haptic_target_hz),
              .unit = "|F| [N]", .series = {decimate(t, f)}, .colours = {{0.80, 0.20, 0.15}}, .labels = {"|force|"}};
  Panel torque{.title = "Torque sent to the device", .unit = "|tau| [N m]", .series = {decimate(t, tq)},
               .colours = {{0.15, 0.35, 0.75}}, .labels = {"|torque|"}};
  Series rate;
  for (const auto& s : report.collision_rates) {
    rate.t.push_back(s.time_s);
    rate.v.push_back(s.rate_hz);
  }
  Panel collision{.title = fmt::format("Collision thread rate (median {:.0f} Hz, min {:.0f} Hz)",
                                       report.collision_rate_median_hz, report.collision_rate_min_hz),
                  .unit = "rate [Hz]", .series = {rate}, .colours = {{0.15, 0.55, 0.25}},
                  .labels = {"collision steps / s (100 ms windows)"},
                  .target = report.collision_target_hz > 0 ? report.collision_target_hz : -1.0};

  std::vector<Panel> panels{force, torque, collision};
  for (const auto& soft : report.soft) panels.push_back(indentation_panel(soft));
  return write_panels(panels, t_max, png);
}

Status write_exploration_plot(const std::string& scene,
                              const std::vector<exploration::ObjectExploration>& objects,
                              const std::filesystem::path& png) {
  std::vector<Panel> panels;
  double t_max = 0.0;
  for (const auto& o : objects) {
    // the first press and its release (the force against time at the press's constant speed is
    // the force against depth: the stiffness), then the strokes and the contour, back to back
    // (the other presses, the moves and the taps between them left out)
    std::vector<double> t_press, pressed;
    bool pressing = false;
    for (const auto& s : o.trace.samples) {
      const bool first = (s.phase == exploration::ExplorePhase::kPress && s.leg <= 0) ||
                         (pressing && s.phase == exploration::ExplorePhase::kRelease);
      if (!first && pressing) break;
      pressing = pressing || first;
      if (!first) continue;
      t_press.push_back(s.time_s);
      pressed.push_back(norm(s.force));
    }
    for (double& x : t_press) x -= t_press.front();
    const double press_end = t_press.empty() ? 0.0 : t_press.back() + 0.2;
    std::vector<double> t, normal, friction;
    double last = -1.0, shift = 0.0;
    for (const auto& f : exploration::stroke_forces(o.trace)) {
      if (last >= 0.0 && f.time_s - last > 0.01) shift += f.time_s - last - 0.01;  // close the gaps
      last = f.time_s;
      t.push_back(f.time_s - shift);
      normal.push_back(f.normal_n);
      friction.push_back(std::max(0.0, f.tangential_n));
    }
    if (!t.empty()) {
      const double t0 = t.front() - press_end;
      for (double& x : t) x -= t0;
      t_max = std::max(t_max, t.back());
    }
    const auto& e = o.estimate;
    panels.push_back(Panel{
        .title =
            fmt::format("{}: {} (k {}, mu_s {}, mu_d {}, period {})", scene, o.object,
                        e.stiffness_n_per_mm ? fmt::format("{:.2f} N/mm", *e.stiffness_n_per_mm) : "none",
                        e.friction_static ? fmt::format("{:.2f}", *e.friction_static) : "none",
                        e.friction_dynamic ? fmt::format("{:.2f}", *e.friction_dynamic) : "none",
                        e.texture_period_m ? fmt::format("{:.2f} mm", *e.texture_period_m * 1e3) : "none"),
        .unit = "force [N]",
        .series = {decimate(t_press, pressed), decimate(t, normal), decimate(t, friction)},
        .colours = {{0.20, 0.60, 0.25}, {0.80, 0.20, 0.15}, {0.15, 0.35, 0.75}},
        .labels = {fmt::format("press and release at {:.0f} mm/s", o.trace.options.press_speed_m_per_s * 1e3),
                   "normal force while stroking", "friction (against the motion)"}});
  }
  if (panels.empty()) return Error{fmt::format("{}: nothing was explored to plot", png.string())};
  return write_panels(panels, t_max, png);
}

}  // namespace uh::cli
