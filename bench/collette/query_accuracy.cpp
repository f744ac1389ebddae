// Accuracy of the volume query against the sphere count, on the 69,666-triangle bunny.
//
// For each sphere count: pack, build, and compare the packing intersection volume and restoring
// direction at the benchmark's deep pose (B rotated 30 deg about Y, 25 % of the x-extent past
// first contact, first contact found on the sampled overlap) with the true mesh intersection
// volume and its gradient, both from stratified point counting with MeshInside (cells^3 samples
// of A's box). Prints a Markdown table.
//
// usage: uh_collette_query_accuracy [cells=48]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <vector>

#include "uh/collette/mesh_import.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"

using namespace uh;
using namespace uh::collette;

int main(int argc, char** argv) {
  const int cells = argc > 1 ? std::atoi(argv[1]) : 48;
  const std::filesystem::path path = std::filesystem::path(UH_SHARED_ASSET_DIR) / "bunny_glmark2_69k.obj";
  auto mesh = load_mesh(path);
  if (!mesh) {
    std::fprintf(stderr, "%s\n", mesh.error().message.c_str());
    return 1;
  }
  const MeshInside inside(*mesh);
  const Aabb box = mesh_bounds(*mesh);
  const Vec3 size = box.max - box.min;
  const Vec3 c = 0.5 * (box.min + box.max);
  const double cell_volume = size.x * size.y * size.z / (static_cast<double>(cells) * cells * cells);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> in_a;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j)
      for (int k = 0; k < cells; ++k) {
        const Vec3 p{box.min.x + (i + u(rng)) / cells * size.x, box.min.y + (j + u(rng)) / cells * size.y,
                     box.min.z + (k + u(rng)) / cells * size.z};
        if (inside.contains(p)) in_a.push_back(p);
      }
  auto true_volume = [&](const Pose& b_in_a) {
    const Pose a_to_b = inverse(b_in_a);
    std::size_t n = 0;
    for (const Vec3& p : in_a) n += inside.contains(transform_point(a_to_b, p)) ? 1u : 0u;
    return static_cast<double>(n) * cell_volume;
  };
  const Quat rot = quat_from_axis_angle({0, 1, 0}, 30.0 * kPi / 180.0);
  auto pose_at = [&](double x) { return Pose{rot, c + Vec3{x, 0, 0} - rotate(rot, c)}; };
  // first contact of the meshes along +x, by bisection on the sampled overlap (to one sample)
  double lo = 0.0, hi = 2.0 * size.x;
  for (int i = 0; i < 20; ++i) {
    const double mid = 0.5 * (lo + hi);
    (true_volume(pose_at(mid)) > 0.0 ? lo : hi) = mid;
  }
  const Pose deep = pose_at(hi - 0.25 * size.x);
  const double v_true = true_volume(deep);
  const double h = 0.02 * size.x;
  Vec3 grad;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 d{};
    (axis == 0 ? d.x : axis == 1 ? d.y : d.z) = h;
    (axis == 0 ? grad.x : axis == 1 ? grad.y : grad.z) =
        (true_volume({deep.rotation, deep.position + d}) - true_volume({deep.rotation, deep.position - d})) / (2.0 * h);
  }
  const Vec3 true_dir = normalized(-grad);
  std::printf("mesh %s: %zu triangles, volume %.4f, sampled %.4f (%d^3 cells); deep pose x %.4f, true overlap %.4f\n\n",
              path.filename().c_str(), mesh->triangles.size(), mesh_volume(*mesh),
              static_cast<double>(in_a.size()) * cell_volume, cells, hi - 0.25 * size.x, v_true);
  std::printf("| spheres | coverage | max gap | packing overlap / true overlap | restoring_direction error [deg] | -volume_gradient error [deg] | query median [us] | pack + build [s] |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  struct Built {
    int count;
    double coverage;
    SphereTree tree;
  };
  std::vector<Built> built;
  for (int count : {1000, 2500, 5000, 10000, 20000}) {
    const auto t0 = std::chrono::steady_clock::now();
    PackingOptions options;
    options.target_sphere_count = count;
    auto packing = pack_spheres(*mesh, options);
    if (!packing) {
      std::fprintf(stderr, "%s\n", packing.error().message.c_str());
      return 1;
    }
    auto tree = build_sphere_tree(packing->spheres);
    if (!tree) return 1;
    const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    VolumeQuery q({.collect_pairs = false});
    std::vector<double> times;
    VolumeQueryResult r{};
    for (int k = 0; k < 200; ++k) {
      const auto t1 = std::chrono::steady_clock::now();
      r = q.run(*tree, *tree, deep);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
    }
    std::sort(times.begin(), times.end());
    const double angle = std::acos(std::clamp(dot(r.restoring_direction, true_dir), -1.0, 1.0)) * 180.0 / kPi;
    const double area_angle = std::acos(std::clamp(dot(normalized(-r.volume_gradient), true_dir), -1.0, 1.0)) * 180.0 / kPi;
    std::printf("| %d | %.3f | %.4f | %.3f | %.1f | %.1f | %.0f | %.1f |\n", tree->leaf_count(), packing->report.coverage,
                packing->report.max_gap, r.total_volume / v_true, angle, area_angle, times[times.size() / 2] * 1e6, build);
    std::fflush(stdout);
    built.push_back({count, packing->report.coverage, std::move(tree).value()});
  }

  // Many deep contacts: B turned about a random axis and pushed along a random direction until the
  // true overlap is a quarter of the extent past first contact; only contacts whose true overlap is
  // at least 3 % of the bunny's volume count (the "deep"). Relative volume error of the raw
  // packing overlap and of the coverage-calibrated estimate (packing overlap / (c_A c_B): each
  // packing fills a share c of its object, so on average it meets c_A c_B of the true overlap).
  const double mesh_vol = mesh_volume(*mesh);
  std::mt19937 pose_rng(2026);
  std::normal_distribution<double> g(0.0, 1.0);
  struct Contact {
    Pose pose;
    double volume;
    Vec3 direction;
  };
  std::vector<Contact> contacts;
  for (int attempt = 0; attempt < 40 && contacts.size() < 16; ++attempt) {
    const Quat q = quat_from_axis_angle(normalized(Vec3{g(pose_rng), g(pose_rng), g(pose_rng)}), 2.0 * kPi * u(pose_rng));
    const Vec3 dir = normalized(Vec3{g(pose_rng), g(pose_rng), g(pose_rng)});
    auto at = [&](double s) { return Pose{q, c + dir * s - rotate(q, c)}; };
    double near_s = 0.0, far_s = 2.0 * norm(size);
    for (int i = 0; i < 16; ++i) {
      const double mid = 0.5 * (near_s + far_s);
      (true_volume(at(mid)) > 0.0 ? near_s : far_s) = mid;
    }
    const Pose pose = at(far_s - 0.25 * size.x);
    const double v = true_volume(pose);
    if (v < 0.03 * mesh_vol) continue;
    Vec3 gr;
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 d{};
      (axis == 0 ? d.x : axis == 1 ? d.y : d.z) = h;
      (axis == 0 ? gr.x : axis == 1 ? gr.y : gr.z) =
          (true_volume({pose.rotation, pose.position + d}) - true_volume({pose.rotation, pose.position - d})) / (2.0 * h);
    }
    contacts.push_back({pose, v, normalized(-gr)});
  }
  std::printf("\n%zu deep contacts (random turn and approach direction, 25 %% of the x-extent past first contact,"
              " true overlap >= 3 %% of the volume; true overlap %.3g..%.3g)\n\n",
              contacts.size(), contacts.empty() ? 0.0 : std::min_element(contacts.begin(), contacts.end(), [](auto& x, auto& y) { return x.volume < y.volume; })->volume,
              contacts.empty() ? 0.0 : std::max_element(contacts.begin(), contacts.end(), [](auto& x, auto& y) { return x.volume < y.volume; })->volume);
  std::printf("| spheres | median rel. error, raw packing overlap | median rel. error, calibrated (/ c^2) | max rel. error, calibrated |"
              " median / max restoring_direction error [deg] | median / max -volume_gradient error [deg] |\n");
  std::printf("|---|---|---|---|---|---|\n");
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
  };
  auto largest = [](const std::vector<double>& v) {
    double m = 0.0;
    for (double x : v) m = std::max(m, x);
    return m;
  };
  if (contacts.empty()) {
    std::fprintf(stderr, "no deep contact found\n");
    return 1;
  }
  for (const Built& b : built) {
    VolumeQuery q({.collect_pairs = false});
    std::vector<double> raw, calibrated, dir_err, grad_err;
    for (const Contact& k : contacts) {
      const VolumeQueryResult& r = q.run(b.tree, b.tree, k.pose);
      raw.push_back(std::abs(r.total_volume / k.volume - 1.0));
      calibrated.push_back(std::abs(r.total_volume / (b.coverage * b.coverage) / k.volume - 1.0));
      dir_err.push_back(std::acos(std::clamp(dot(r.restoring_direction, k.direction), -1.0, 1.0)) * 180.0 / kPi);
      grad_err.push_back(std::acos(std::clamp(dot(normalized(-r.volume_gradient), k.direction), -1.0, 1.0)) * 180.0 / kPi);
    }
    std::printf("| %d | %.1f %% | %.1f %% | %.1f %% | %.1f / %.1f | %.1f / %.1f |\n", b.count, 100.0 * median(raw),
                100.0 * median(calibrated), 100.0 * largest(calibrated), median(dir_err), largest(dir_err), median(grad_err),
                largest(grad_err));
    std::fflush(stdout);
  }
  return 0;
}
