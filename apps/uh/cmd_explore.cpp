// uh explore SCENE [--object NAME] [--json] [--plot OUT.png] [--seed N]
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "progress_bar.hpp"
#include "session_plot.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/exploration/exploration.hpp"

namespace uh::cli {
namespace {

struct ExploreArgs {
  std::string scene;
  std::string object;
  bool json = false;
  std::string plot;
  std::uint64_t seed = 1;
  double haptic_hz = 0.0;
  int ticks_per_collision = 1;
  std::string proxy;  // "on", "off" or "" (the scene's)
};

nlohmann::json optional_number(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

std::string shown(const std::optional<double>& v, const char* format_unit) {
  return v ? fmt::format(fmt::runtime(format_unit), *v) : std::string("none");
}

// Whether the stiffness read is the proxy's passive limit rather than the material's (the presses
// read a spring within a few per cent of it: the material is at least that stiff)
bool at_rendered_limit(const exploration::ObjectExploration& o) {
  const auto& k = o.estimate.stiffness_n_per_mm;
  return o.rendered_stiffness_limit_n_per_m > 0.0 && k && *k * 1e3 >= 0.95 * o.rendered_stiffness_limit_n_per_m;
}

int explore(const ExploreArgs& args) {
  auto scene = controllers::load_scene(args.scene);
  if (!scene) return fail(scene.error().message);
  exploration::ExploreOptions options;
  options.seed = args.seed;
  if (args.haptic_hz > 0.0) options.haptic_hz = args.haptic_hz;
  options.ticks_per_collision_step = args.ticks_per_collision;
  controllers::SessionOptions session;
  session.cache_dir = controllers::default_cache_dir();
  if (!args.proxy.empty()) session.proxy = args.proxy == "on";
  StagedProgress bars;
  session.build_progress = bars.callback();
  auto explored = exploration::explore_scene(*scene, args.object, options, session);
  bars.finish();
  if (!explored) return fail(explored.error().message);
  if (!args.plot.empty())
    if (auto plotted = write_exploration_plot(scene->name, *explored, args.plot); !plotted)
      return fail(plotted.error().message);
  if (args.json) {
    nlohmann::json objects = nlohmann::json::array();
    for (const auto& o : *explored) {
      const auto& e = o.estimate;
      objects.push_back(
          {{"name", o.object},
           {"stiffness_n_per_mm", optional_number(e.stiffness_n_per_mm)},
           {"stiffness_per_press_n_per_mm", e.stiffness_per_press_n_per_mm},
           {"rendered_stiffness_limit_n_per_mm", o.rendered_stiffness_limit_n_per_m > 0.0
                                                     ? nlohmann::json(o.rendered_stiffness_limit_n_per_m * 1e-3)
                                                     : nlohmann::json(nullptr)},
           {"stiffness_is_rendered_limit", at_rendered_limit(o)},
           {"press_reach_m", optional_number(e.press_reach_m)},
           {"damping_n_s_per_m", optional_number(e.damping_n_s_per_m)},
           {"damping_per_press_n_s_per_m", e.damping_per_press_n_s_per_m},
           {"friction_static", optional_number(e.friction_static)},
           {"friction_dynamic", optional_number(e.friction_dynamic)},
           {"texture_period_m", optional_number(e.texture_period_m)},
           {"texture_ripple_n", e.texture_ripple_n},
           {"texture_period_along_strokes_m",
            {e.period_axis_m[0] > 0.0 ? nlohmann::json(e.period_axis_m[0]) : nlohmann::json(nullptr),
             e.period_axis_m[1] > 0.0 ? nlohmann::json(e.period_axis_m[1]) : nlohmann::json(nullptr)}},
           {"texture_ripple_along_strokes_n", {e.ripple_axis_n[0], e.ripple_axis_n[1]}},
           {"texture_sine_share_along_strokes", {e.sine_share_axis[0], e.sine_share_axis[1]}},
           {"texture_wave_share", e.texture_wave_share},
           {"work_on_hand_j", o.work_on_hand_j},
           {"simulated_s", o.simulated_s},
           {"haptic_ticks", o.haptic_ticks}});
    }
    const nlohmann::json out{{"scene", scene->name}, {"seed", args.seed}, {"objects", objects}};
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::printf("scene %s: explored %zu object(s) in simulated time (seed %llu)\n", scene->name.c_str(),
              explored->size(), static_cast<unsigned long long>(args.seed));
  for (const auto& o : *explored) {
    const auto& e = o.estimate;
    std::printf("  %s\n", o.object.c_str());
    std::printf(
        "    stiffness  %s, pressed %s past first contact\n",
        shown(e.stiffness_n_per_mm, "{:.3f} N/mm").c_str(),
        shown(e.press_reach_m ? std::optional<double>(*e.press_reach_m * 1e3) : std::nullopt, "{:.2f} mm")
            .c_str());
    if (at_rendered_limit(o))
      std::printf(
          "    (the rendered stiffness: through the proxy the device renders at most %.3f N/mm passively, and the "
          "material is stiffer; --proxy off reads the material's)\n",
          o.rendered_stiffness_limit_n_per_m * 1e-3);
    if (e.press_reach_m && options.press_depth_m && *e.press_reach_m < 0.95 * *options.press_depth_m)
      std::printf(
          "    (the force limit stopped the presses short of %.2f mm: a packed face reads low there)\n",
          *options.press_depth_m * 1e3);
    // (a damping that rounds to zero prints as 0.000, not -0.000)
    const std::optional<double> damping =
        e.damping_n_s_per_m ? std::optional<double>(std::fabs(*e.damping_n_s_per_m) < 5e-4 ? 0.0 : *e.damping_n_s_per_m)
                            : std::nullopt;
    std::printf("    damping    %s\n", shown(damping, "{:.3f} N s/m").c_str());
    std::printf("    friction   static %s, dynamic %s\n", shown(e.friction_static, "{:.3f}").c_str(),
                shown(e.friction_dynamic, "{:.3f}").c_str());
    std::printf("    texture    period %s, ripple %.3f N RMS\n",
                shown(e.texture_period_m, "{:.5f} m").c_str(), e.texture_ripple_n);
    std::printf("    %.1f s simulated, %llu ticks; energy into the hand %.5f J\n", o.simulated_s,
                static_cast<unsigned long long>(o.haptic_ticks), o.work_on_hand_j);
  }
  if (!args.plot.empty()) std::printf("  plot -> %s\n", args.plot.c_str());
  return 0;
}

}  // namespace

void add_explore_command(CLI::App& app, CommandRunner& runner) {
  static ExploreArgs args;
  auto* e = app.add_subcommand(
      "explore",
      "explore each object of a scene with a scripted hand in simulated time (press, strokes, a contour, "
      "taps) "
      "and estimate its material from the position and force trace: stiffness, friction, texture");
  e->add_option("scene", args.scene, "scene file (JSON)")->required()->check(CLI::ExistingFile);
  e->add_option("--object", args.object, "explore only the object of this name");
  e->add_flag("--json", args.json, "print one JSON object with the estimates per object");
  e->add_option("--plot", args.plot, "write a PNG of the forces felt while stroking each object");
  e->add_option("--seed", args.seed, "where on each object and in which directions to stroke (default 1)");
  e->add_option("--haptic-hz", args.haptic_hz, "override the haptic rate [Hz]")
      ->check(CLI::Range(1.0, 10000.0));
  e->add_option("--proxy", args.proxy, "explore through the 6-DOF proxy (on) or the penalty path (off), whatever the scene says")
      ->check(CLI::IsMember({"on", "off"}));
  e->add_option("--ticks-per-collision", args.ticks_per_collision,
                "haptic ticks per collision step (default 1)")
      ->check(CLI::Range(1, 1000));
  e->callback([&runner] { runner = [] { return explore(args); }; });
}

}  // namespace uh::cli
