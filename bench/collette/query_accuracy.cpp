// Accuracy of the volume query and of the two force laws' directions against the true mesh
// intersection volume (stratified point counting with MeshInside) and its gradient (central
// differences of it).
//
// Part 1, always: several mesh pairs (the repository's bunny and stylus, generated box, ball and
// torus; the shared assets' 69k bunny, screw, nozzle and torus when ../shared/assets is present),
// each packed with 10,000 spheres, at deep contacts (random turn and approach direction, pushed
// 5-30 % of the smaller object's diagonal past the packings' first contact). Per pair: median and
// worst angle between the true restoring direction (minus the gradient of the true overlap w.r.t.
// B's translation) and the static force direction of each law (paper, eq. 1: the
// lens-volume-weighted normals; gradient: minus the gradient of the packings' overlap volume), and
// the error of volume_estimate = packing overlap / (c_A c_B).
//
// Part 2, when the 69,666-triangle bunny of ../shared/assets is present: bunny against bunny over
// the sphere count, at the query benchmark's deep pose and at 16 random deep contacts.
//
// usage: uh_collette_query_accuracy [cells=48] [contacts per pair=12]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "uh/collette/mesh_import.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"
// the tests' generated meshes (unit cube, icosphere, torus)
#include "mesh_test_support.hpp"

using namespace uh;
using namespace uh::collette;

namespace {

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
}

double largest_of(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, x);
  return m;
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(dot(normalized(a), normalized(b)), -1.0, 1.0)) * 180.0 / kPi;
}

double diagonal(const TriangleMesh& m) {
  const Aabb b = mesh_bounds(m);
  return norm(b.max - b.min);
}

// The mesh moved so that its box centre is at the origin and scaled to the given box diagonal.
TriangleMesh normalised(TriangleMesh m, double target_diagonal) {
  const Aabb b = mesh_bounds(m);
  const Vec3 c = 0.5 * (b.min + b.max);
  const double s = target_diagonal / norm(b.max - b.min);
  for (Vec3& v : m.vertices) v = s * (v - c);
  return m;
}

// The unit cube of the tests stretched to x by y by z.
TriangleMesh box_mesh(double x, double y, double z) {
  TriangleMesh m = test::unit_cube();
  for (Vec3& v : m.vertices) v = {v.x * x, v.y * y, v.z * z};
  return m;
}

// A mesh ready for the table: validated, centred, scaled, packed.
struct Body {
  std::string name;
  TriangleMesh mesh;
  SphereTree tree;
  double coverage = 0.0;
};

// Loads (or takes) a mesh, normalises it to `diag`, validates and packs it with 10,000 spheres.
bool make_body(const std::string& name, Result<TriangleMesh> source, double diag, Body& out) {
  if (!source) {
    std::fprintf(stderr, "skipping %s: %s\n", name.c_str(), source.error().message.c_str());
    return false;
  }
  auto mesh = validate_mesh(normalised(std::move(source).value(), diag));
  if (!mesh) {
    std::fprintf(stderr, "skipping %s: %s\n", name.c_str(), mesh.error().message.c_str());
    return false;
  }
  auto packing = pack_spheres(*mesh, {.target_sphere_count = 10000});
  if (!packing) {
    std::fprintf(stderr, "skipping %s: %s\n", name.c_str(), packing.error().message.c_str());
    return false;
  }
  auto tree = build_sphere_tree(packing->spheres);
  if (!tree) return false;
  out = Body{name, std::move(mesh).value(), std::move(tree).value(), packing->report.coverage};
  return true;
}

// The true overlap of A and B (B placed by b_in_a), by stratified samples of the smaller one.
class TrueOverlap {
 public:
  TrueOverlap(const TriangleMesh& a, const TriangleMesh& b, int cells)
      : sample_b_(mesh_volume(b) <= mesh_volume(a)), other_(sample_b_ ? a : b) {
    const TriangleMesh& sampled = sample_b_ ? b : a;
    const MeshInside inside(sampled);
    const Aabb box = mesh_bounds(sampled);
    const Vec3 size = box.max - box.min;
    cell_volume_ = size.x * size.y * size.z / (static_cast<double>(cells) * cells * cells);
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j)
        for (int k = 0; k < cells; ++k) {
          const Vec3 p{box.min.x + (i + u(rng)) / cells * size.x, box.min.y + (j + u(rng)) / cells * size.y,
                       box.min.z + (k + u(rng)) / cells * size.z};
          if (inside.contains(p)) samples_.push_back(p);
        }
  }
  // the sampled mesh's volume as the samples see it (a check of the counting)
  double sampled_volume() const { return static_cast<double>(samples_.size()) * cell_volume_; }
  double volume(const Pose& b_in_a) const {
    const Pose to_other = sample_b_ ? b_in_a : inverse(b_in_a);
    std::size_t n = 0;
    for (const Vec3& p : samples_) n += other_.contains(transform_point(to_other, p)) ? 1u : 0u;
    return static_cast<double>(n) * cell_volume_;
  }
  // d volume / d (translation of B), central differences with step h
  Vec3 gradient(const Pose& b_in_a, double h) const {
    Vec3 g;
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 d{};
      (axis == 0 ? d.x : axis == 1 ? d.y : d.z) = h;
      (axis == 0   ? g.x
       : axis == 1 ? g.y
                   : g.z) =
          (volume({b_in_a.rotation, b_in_a.position + d}) - volume({b_in_a.rotation, b_in_a.position - d})) /
          (2 * h);
    }
    return g;
  }

 private:
  bool sample_b_;
  MeshInside other_;
  std::vector<Vec3> samples_;
  double cell_volume_ = 0.0;
};

// Part 1: the table over mesh pairs. Returns false when nothing could be measured.
bool force_direction_table(int cells, int contacts_per_pair) {
  const std::filesystem::path repo = std::filesystem::path(UH_ASSET_DIR) / "meshes";
  const std::filesystem::path shared(UH_SHARED_ASSET_DIR);
  std::vector<std::unique_ptr<Body>> bodies;
  const auto body = [&](const std::string& name, Result<TriangleMesh> source, double diag) -> const Body* {
    auto b = std::make_unique<Body>();
    if (!make_body(name, std::move(source), diag, *b)) return nullptr;
    bodies.push_back(std::move(b));
    return bodies.back().get();
  };
  struct Pair {
    const Body* a;
    const Body* b;
  };
  std::vector<Pair> pairs;
  const auto add = [&](const Body* a, const Body* b) {
    if (a != nullptr && b != nullptr) pairs.push_back({a, b});
  };
  const Body* bunny = body("bunny 3.7k", load_mesh(repo / "bunny_npm_3674.obj"), 10.0);
  const Body* bunny_small = body("bunny 3.7k", load_mesh(repo / "bunny_npm_3674.obj"), 6.0);
  const Body* stylus = body("stylus", load_mesh(repo / "stylus.obj"), 6.0);
  const Body* torus = body("torus (generated)", test::torus(1.0, 0.35, 64, 32), 10.0);
  const Body* box = body("box (generated)", box_mesh(1.0, 0.6, 0.4), 6.0);
  const Body* big_box = body("box (generated)", box_mesh(1.0, 0.6, 0.4), 10.0);
  const Body* ball = body("ball (generated)", test::icosphere(1.0, 4), 5.0);
  add(bunny, bunny);
  add(bunny, stylus);
  add(torus, box);
  add(torus, bunny_small);
  add(big_box, ball);
  if (std::filesystem::exists(shared / "bunny_glmark2_69k.obj")) {
    const Body* bunny69 = body("bunny 69k (shared)", load_mesh(shared / "bunny_glmark2_69k.obj"), 10.0);
    const Body* screw = body("screw M3x10 (shared)", load_mesh(shared / "tool_screw_M3x10_prusa.stl"), 5.0);
    const Body* nozzle = body("nozzle (shared)", load_mesh(shared / "tool_nozzle_cura.stl"), 5.0);
    const Body* torus2 = body("torus (shared)", load_mesh(shared / "torus_prusa.stl"), 10.0);
    add(bunny69, bunny69);
    add(bunny69, screw);
    add(torus2, nozzle);
  }
  if (pairs.empty()) return false;

  std::printf(
      "Force directions at deep contacts, every mesh packed with 10,000 spheres (%d^3 samples of the smaller"
      " mesh's box for the true overlap; %d contacts per pair, random turn and approach, 5-30 %% of the "
      "smaller"
      " diagonal past the packings' first contact, true overlap >= 1 %% of the smaller volume)\n\n",
      cells, contacts_per_pair);
  std::printf(
      "| A | B | coverage A / B | contacts | paper law direction error median / worst [deg] |"
      " gradient law direction error median / worst [deg] | volume_estimate error median / worst |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  std::vector<double> all_paper, all_gradient, all_volume;
  std::mt19937 rng(2026);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  VolumeQuery q({.collect_pairs = false});
  for (const Pair& pair : pairs) {
    const Body& a = *pair.a;
    const Body& b = *pair.b;
    const TrueOverlap truth(a.mesh, b.mesh, cells);
    const double small_diag = std::min(diagonal(a.mesh), diagonal(b.mesh));
    const double small_volume = std::min(mesh_volume(a.mesh), mesh_volume(b.mesh));
    const double h = 0.02 * small_diag;
    std::vector<double> paper, gradient, volume;
    for (int attempt = 0;
         attempt < 4 * contacts_per_pair && static_cast<int>(paper.size()) < contacts_per_pair; ++attempt) {
      const Quat turn = quat_from_axis_angle(normalized(Vec3{g(rng), g(rng), g(rng)}), 2 * kPi * u(rng));
      const Vec3 dir = normalized(Vec3{g(rng), g(rng), g(rng)});
      const auto at = [&](double s) { return Pose{turn, dir * s}; };  // both meshes are centred
      // first contact of the packings along -dir, by bisection on the packing overlap
      double near_s = 0.0, far_s = diagonal(a.mesh) + diagonal(b.mesh);
      if (!(q.run(a.tree, b.tree, at(near_s)).total_volume > 0.0)) continue;  // e.g. B in the torus's hole
      for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (near_s + far_s);
        (q.run(a.tree, b.tree, at(mid)).total_volume > 0.0 ? near_s : far_s) = mid;
      }
      const Pose pose = at(far_s - (0.05 + 0.25 * u(rng)) * small_diag);
      const double v = truth.volume(pose);
      if (v < 0.01 * small_volume) continue;
      const VolumeQueryResult& r = q.run(a.tree, b.tree, pose);
      if (!(r.total_volume > 0.0)) continue;
      const Vec3 true_direction = -truth.gradient(pose, h);
      paper.push_back(angle_deg(r.weighted_normal_sum, true_direction));
      gradient.push_back(angle_deg(-r.volume_gradient, true_direction));
      volume.push_back(std::abs(r.total_volume / (a.coverage * b.coverage) / v - 1.0));
    }
    std::printf(
        "| %s, %zu triangles | %s, %zu triangles | %.3f / %.3f | %zu | %.1f / %.1f | %.1f / %.1f | %.1f %% / "
        "%.1f %% |\n",
        a.name.c_str(), a.mesh.triangles.size(), b.name.c_str(), b.mesh.triangles.size(), a.coverage,
        b.coverage, paper.size(), median_of(paper), largest_of(paper), median_of(gradient),
        largest_of(gradient), 100.0 * median_of(volume), 100.0 * largest_of(volume));
    std::fflush(stdout);
    all_paper.insert(all_paper.end(), paper.begin(), paper.end());
    all_gradient.insert(all_gradient.end(), gradient.begin(), gradient.end());
    all_volume.insert(all_volume.end(), volume.begin(), volume.end());
  }
  std::printf("| all pairs | | | %zu | %.1f / %.1f | %.1f / %.1f | %.1f %% / %.1f %% |\n\n", all_paper.size(),
              median_of(all_paper), largest_of(all_paper), median_of(all_gradient), largest_of(all_gradient),
              100.0 * median_of(all_volume), 100.0 * largest_of(all_volume));
  return !all_paper.empty();
}

}  // namespace

int main(int argc, char** argv) {
  const int cells = argc > 1 ? std::atoi(argv[1]) : 48;
  const int contacts_per_pair = argc > 2 ? std::atoi(argv[2]) : 12;
  if (!force_direction_table(cells, contacts_per_pair)) {
    std::fprintf(stderr, "no mesh pair could be measured\n");
    return 1;
  }
  const std::filesystem::path path = std::filesystem::path(UH_SHARED_ASSET_DIR) / "bunny_glmark2_69k.obj";
  if (!std::filesystem::exists(path)) {
    std::printf("(%s is absent: the table over the sphere count is left out)\n", path.c_str());
    return 0;
  }
  auto mesh = load_mesh(path);
  if (!mesh) {
    std::fprintf(stderr, "%s\n", mesh.error().message.c_str());
    return 1;
  }
  const Aabb box = mesh_bounds(*mesh);
  const Vec3 size = box.max - box.min;
  const Vec3 c = 0.5 * (box.min + box.max);
  const TrueOverlap truth(*mesh, *mesh, cells);
  const auto true_volume = [&](const Pose& b_in_a) { return truth.volume(b_in_a); };
  std::uniform_real_distribution<double> u(0.0, 1.0);
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
  std::printf(
      "mesh %s: %zu triangles, volume %.4f, sampled %.4f (%d^3 cells); deep pose x %.4f, true overlap "
      "%.4f\n\n",
      path.filename().c_str(), mesh->triangles.size(), mesh_volume(*mesh), truth.sampled_volume(), cells,
      hi - 0.25 * size.x, v_true);
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
  const auto median = median_of;
  const auto largest = largest_of;
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
