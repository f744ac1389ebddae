#include "uh/museum_artifacts/artifact.hpp"

#include <cmath>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "uh/collette/ist_file.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/core/atomic_file_writer.hpp"

namespace uh::museum_artifacts {

using museum::Difficulty;

const char* to_string(ArtifactKind kind) {
  switch (kind) {
    case ArtifactKind::amphora:
      return "amphora";
    case ArtifactKind::bowl:
      return "bowl";
    case ArtifactKind::coin:
      return "coin";
    case ArtifactKind::tablet:
      return "tablet";
    case ArtifactKind::scarab:
      return "scarab";
    case ArtifactKind::goblet:
      return "goblet";
  }
  return "unknown";
}

std::optional<ArtifactKind> artifact_kind(std::string_view name) {
  for (const ArtifactKind k : kArtifactKinds)
    if (name == to_string(k)) return k;
  return std::nullopt;
}

namespace {

constexpr double kPi = std::numbers::pi;

// a bump of height 1 at 0 falling off with `width` (the standard deviation)
double bump(double d, double width) { return std::exp(-0.5 * (d / width) * (d / width)); }

// smooth step from 0 (x <= a) to 1 (x >= b)
double smooth_step(double x, double a, double b) {
  const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// a lathe profile through control points (z, r), eased between them (flat at each point)
struct Profile {
  std::vector<std::pair<double, double>> points;
  double operator()(double z) const {
    if (z <= points.front().first) return points.front().second;
    for (std::size_t k = 0; k + 1 < points.size(); ++k) {
      const auto [z0, r0] = points[k];
      const auto [z1, r1] = points[k + 1];
      if (z <= z1) return r0 + (r1 - r0) * 0.5 * (1.0 - std::cos(kPi * (z - z0) / (z1 - z0)));
    }
    return points.back().second;
  }
};

// a solid of revolution about z: rings from z0 to z1 with radius radius(z, theta) > 0, closed by
// flat caps (a fan around the axis at each end)
template <typename Radius>
collette::TriangleMesh lathe(int rings, int segments, double z0, double z1, Radius radius) {
  collette::TriangleMesh mesh;
  for (int i = 0; i <= rings; ++i) {
    const double z = z0 + (z1 - z0) * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double theta = 2.0 * kPi * j / segments;
      const double r = radius(z, theta);
      mesh.vertices.push_back({r * std::cos(theta), r * std::sin(theta), z});
    }
  }
  const auto at = [&](int i, int j) { return static_cast<std::int32_t>(i * segments + (j % segments)); };
  const auto bottom = static_cast<std::int32_t>(mesh.vertices.size());
  mesh.vertices.push_back({0.0, 0.0, z0});
  const auto top = static_cast<std::int32_t>(mesh.vertices.size());
  mesh.vertices.push_back({0.0, 0.0, z1});
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      mesh.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  }
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({bottom, at(0, j + 1), at(0, j)});
    mesh.triangles.push_back({top, at(rings, j), at(rings, j + 1)});
  }
  return mesh;
}

// a slab on z = 0 whose top is height(x, y) over [-w/2, w/2] x [-d/2, d/2], on an nx x ny grid
template <typename Height>
collette::TriangleMesh relief_slab(int nx, int ny, double w, double d, Height height) {
  collette::TriangleMesh mesh;
  const int row = nx + 1;
  const int layer = row * (ny + 1);
  for (int level = 0; level < 2; ++level) {
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        const double x = -0.5 * w + w * i / nx;
        const double y = -0.5 * d + d * j / ny;
        mesh.vertices.push_back({x, y, level == 0 ? 0.0 : height(x, y)});
      }
    }
  }
  const auto bot = [&](int i, int j) { return static_cast<std::int32_t>(j * row + i); };
  const auto top = [&](int i, int j) { return static_cast<std::int32_t>(layer + j * row + i); };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      mesh.triangles.push_back({top(i, j), top(i + 1, j), top(i + 1, j + 1)});
      mesh.triangles.push_back({top(i, j), top(i + 1, j + 1), top(i, j + 1)});
      mesh.triangles.push_back({bot(i, j), bot(i + 1, j + 1), bot(i + 1, j)});
      mesh.triangles.push_back({bot(i, j), bot(i, j + 1), bot(i + 1, j + 1)});
    }
  }
  for (int i = 0; i < nx; ++i) {
    // y = -d/2 faces -y, y = +d/2 faces +y
    mesh.triangles.push_back({bot(i, 0), bot(i + 1, 0), top(i + 1, 0)});
    mesh.triangles.push_back({bot(i, 0), top(i + 1, 0), top(i, 0)});
    mesh.triangles.push_back({bot(i + 1, ny), bot(i, ny), top(i, ny)});
    mesh.triangles.push_back({bot(i + 1, ny), top(i, ny), top(i + 1, ny)});
  }
  for (int j = 0; j < ny; ++j) {
    // x = -w/2 faces -x, x = +w/2 faces +x
    mesh.triangles.push_back({bot(0, j), top(0, j), top(0, j + 1)});
    mesh.triangles.push_back({bot(0, j), top(0, j + 1), bot(0, j + 1)});
    mesh.triangles.push_back({bot(nx, j), top(nx, j + 1), top(nx, j)});
    mesh.triangles.push_back({bot(nx, j), bot(nx, j + 1), top(nx, j + 1)});
  }
  return mesh;
}

bool easy(Difficulty d) { return d == Difficulty::easy; }

// a piece's surface: the gradient law's stiffness [N/m^2] and Coulomb friction
forcecomp::Material surface_material(double stiffness, double friction_static, double friction_dynamic) {
  forcecomp::Material m;
  m.has_stiffness = true;
  m.stiffness = stiffness;
  m.has_friction = true;
  m.friction_static = friction_static;
  m.friction_dynamic = friction_dynamic;
  return m;
}

// grooves of depth 1 every `spacing`, each `width` wide (standard deviation), across [-half, half]
double grooves(double x, double spacing, double width, double half) {
  double g = 0.0;
  for (double c = -std::floor(half / spacing) * spacing; c <= half; c += spacing)
    g = std::max(g, bump(x - c, width));
  return g;
}

}  // namespace

Tell tell(ArtifactKind kind, Difficulty difficulty) {
  const bool e = easy(difficulty);
  switch (kind) {
    case ArtifactKind::amphora: {
      const double h = e ? 0.003 : 0.0012;
      return {"missing ridge",
              fmt::format(
                  "the genuine amphora has a ridge {:.1f} mm high around its shoulder; the forgery has none",
                  h * 1e3),
              h, 0.003};
    }
    case ArtifactKind::bowl: {
      const double h = e ? 0.003 : 0.0012;
      return {"dent", fmt::format("the forgery has a dent {:.1f} mm deep in its side", h * 1e3), h, 0.006};
    }
    case ArtifactKind::coin: {
      const double h = e ? 0.0015 : 0.001;
      return {"groove spacing",
              fmt::format("the genuine coin's edge has 24 grooves {:.1f} mm deep; the forgery's has {}",
                          h * 1e3, e ? 14 : 18),
              h, 2.0 * kPi * 0.035 / 24.0};
    }
    case ArtifactKind::tablet: {
      const double h = e ? 0.002 : 0.0012;
      return {"groove spacing",
              fmt::format("the genuine tablet's grooves are 8 mm apart; the forgery's {} mm ({:.1f} mm deep)",
                          e ? 14 : 11, h * 1e3),
              h, 0.008};
    }
    case ArtifactKind::scarab: {
      const double h = e ? 0.002 : 0.0009;
      return {
          "missing ridge",
          fmt::format("the genuine scarab has a ridge {:.1f} mm high along its back; the forgery has none",
                      h * 1e3),
          h, 0.0024};
    }
    case ArtifactKind::goblet: {
      const double h = e ? 0.002 : 0.0009;
      return {"seam",
              fmt::format("the forgery has a mould seam {:.1f} mm high up the side of its cup", h * 1e3), h,
              0.003};
    }
  }
  return {};
}

MaterialTell material_tell(ArtifactKind kind, Difficulty difficulty) {
  const bool e = easy(difficulty);
  switch (kind) {
    case ArtifactKind::bowl: {
      const double ratio = e ? 0.55 : 0.8;
      return {"stiffness", ratio,
              fmt::format("the forgery is resin, {:.0f} % softer than the glazed genuine bowl",
                          100.0 * (1.0 - ratio))};
    }
    case ArtifactKind::tablet: {
      const double ratio = e ? 1.6 : 1.25;
      return {
          "friction", ratio,
          fmt::format("the forgery is plaster, {:.0f} % grippier than the fired clay of the genuine tablet",
                      100.0 * (ratio - 1.0))};
    }
    case ArtifactKind::goblet: {
      const double ratio = e ? 0.6 : 0.8;
      return {"friction", ratio,
              fmt::format("the forgery is plated, {:.0f} % more slippery than the genuine silver goblet",
                          100.0 * (1.0 - ratio))};
    }
    case ArtifactKind::amphora:
    case ArtifactKind::coin:
    case ArtifactKind::scarab:
      return {};
  }
  return {};
}

forcecomp::Material artifact_material(ArtifactKind kind, Difficulty difficulty, Piece piece) {
  // the genuine pieces' materials: stiffness k [N/m^2] of the gradient law, Coulomb coefficients
  struct Genuine {
    double stiffness, friction_static, friction_dynamic;
  };
  const Genuine g = [kind]() -> Genuine {
    switch (kind) {
      case ArtifactKind::amphora:
        return {1.5e5, 0.45, 0.35};  // fired clay
      case ArtifactKind::bowl:
        // glazed ceramic, as stiff as the stylus feels a surface through the proxy below the
        // coupling's passive stiffness (2 pi r k = 1.38 kN/m): its resin forgery is felt softer
        return {5.5e4, 0.3, 0.22};
      case ArtifactKind::coin:
        return {2.5e5, 0.35, 0.25};  // bronze
      case ArtifactKind::tablet:
        return {1.5e5, 0.4, 0.3};  // fired clay
      case ArtifactKind::scarab:
        return {2.5e5, 0.4, 0.3};  // stone
      case ArtifactKind::goblet:
        return {2.5e5, 0.3, 0.22};  // silver
    }
    return {1.5e5, 0.4, 0.3};
  }();
  forcecomp::Material m = surface_material(g.stiffness, g.friction_static, g.friction_dynamic);
  if (piece == Piece::forgery) {
    const MaterialTell t = material_tell(kind, difficulty);
    if (t.property == "stiffness") m.stiffness *= t.ratio;
    if (t.property == "friction") {
      m.friction_static *= t.ratio;
      m.friction_dynamic *= t.ratio;
    }
  }
  return m;
}

namespace {

// the mesh of a form check_form() accepted
collette::TriangleMesh mesh_of(ArtifactKind kind, const museum::PieceForm& form) {
  const Tell t = tell(kind, form.difficulty);
  const double feature = form.feature;
  collette::TriangleMesh mesh;
  switch (kind) {
    case ArtifactKind::amphora: {
      const Profile p{{{0.0, 0.025}, {0.05, 0.045}, {0.10, 0.015}, {0.12, 0.02}}};
      mesh = lathe(240, 128, 0.0, 0.12,
                   [&](double z, double) { return p(z) + feature * bump(z - 0.075, t.width / 2.0); });
      break;
    }
    case ArtifactKind::bowl: {
      const Profile p{{{0.0, 0.03}, {0.05, 0.06}}};
      mesh = lathe(100, 192, 0.0, 0.05, [&](double z, double theta) {
        // the dent faces +x, halfway up
        const double arc = std::remainder(theta, 2.0 * kPi) * p(z);
        const double dent = feature * bump(std::hypot(z - 0.025, arc), t.width / 2.0);
        return p(z) - dent;
      });
      break;
    }
    case ArtifactKind::coin: {
      const auto count = static_cast<int>(std::lround(feature));
      mesh = lathe(32, 384, 0.0, 0.008, [&](double z, double theta) {
        // rounded rims, the reeding on the band between them
        const double rim = 0.0008 * (1.0 - smooth_step(z, 0.0, 0.0015) * smooth_step(0.008 - z, 0.0, 0.0015));
        const double band = smooth_step(z, 0.0015, 0.0025) * smooth_step(0.008 - z, 0.0015, 0.0025);
        const double reed = 0.5 * (1.0 + std::cos(count * theta));
        return 0.035 - rim - t.depth * band * reed;
      });
      break;
    }
    case ArtifactKind::tablet: {
      const double spacing = feature;
      mesh = relief_slab(180, 60, 0.09, 0.06, [&](double x, double y) {
        // grooves across the tablet, fading out 6 mm before its edges
        const double inside =
            smooth_step(0.045 - std::fabs(x), 0.002, 0.006) * smooth_step(0.03 - std::fabs(y), 0.002, 0.006);
        return 0.012 - t.depth * inside * grooves(x, spacing, 0.0012, 0.04);
      });
      break;
    }
    case ArtifactKind::scarab: {
      mesh = relief_slab(160, 120, 0.08, 0.06, [&](double x, double y) {
        const double e2 = (x / 0.036) * (x / 0.036) + (y / 0.026) * (y / 0.026);
        const double dome = 0.016 * std::sqrt(std::max(0.0, 1.0 - e2));
        // the ridge between the wing cases runs along x on the dome's back
        const double ridge = feature * bump(y, t.width / 2.0) * smooth_step(1.0 - e2, 0.0, 0.3);
        return 0.004 + dome + ridge;
      });
      break;
    }
    case ArtifactKind::goblet: {
      const Profile p{
          {{0.0, 0.03}, {0.008, 0.03}, {0.016, 0.008}, {0.06, 0.008}, {0.085, 0.03}, {0.11, 0.035}}};
      mesh = lathe(220, 256, 0.0, 0.11, [&](double z, double theta) {
        // the seam runs up the cup on the -x side
        const double arc = std::remainder(theta - kPi, 2.0 * kPi) * p(z);
        const double seam = feature * bump(arc, t.width / 2.0) * smooth_step(z, 0.065, 0.075);
        return p(z) + seam;
      });
      break;
    }
  }
  // named by its kind and form only: the file a station writes never says which piece it holds
  mesh.source_name =
      fmt::format("{} ({}, feature {:.4g})", to_string(kind), museum::to_string(form.difficulty), feature);
  return mesh;
}

}  // namespace

museum::PieceForm piece_form(ArtifactKind kind, Difficulty difficulty, Piece piece) {
  const bool genuine = piece == Piece::genuine;
  const double h = tell(kind, difficulty).depth;
  double feature = 0.0;
  switch (kind) {
    case ArtifactKind::amphora:
    case ArtifactKind::scarab:
      feature = genuine ? h : 0.0;  // the genuine piece's ridge
      break;
    case ArtifactKind::bowl:
    case ArtifactKind::goblet:
      feature = genuine ? 0.0 : h;  // the forgery's dent or seam
      break;
    case ArtifactKind::coin:
      feature = genuine ? 24 : (easy(difficulty) ? 14 : 18);  // reeds
      break;
    case ArtifactKind::tablet:
      feature = genuine ? 0.008 : (easy(difficulty) ? 0.014 : 0.011);  // groove spacing [m]
      break;
  }
  const forcecomp::Material m = artifact_material(kind, difficulty, piece);
  return {.kind = to_string(kind),
          .difficulty = difficulty,
          .feature = feature,
          .stiffness = m.stiffness,
          .friction_static = m.friction_static,
          .friction_dynamic = m.friction_dynamic};
}

std::vector<museum::PiecePair> piece_pairs(const museum::Level& level) {
  std::vector<museum::PiecePair> pairs;
  for (const std::string& name : level.artifact_kinds) {
    const auto kind = artifact_kind(name);
    if (!kind) return {};
    pairs.push_back({piece_form(*kind, level.difficulty, Piece::genuine),
                     piece_form(*kind, level.difficulty, Piece::forgery)});
  }
  return pairs;
}

Result<ArtifactKind> check_form(const museum::PieceForm& form) {
  const auto kind = artifact_kind(form.kind);
  if (!kind) return Error{fmt::format("'{}' is no artifact kind", form.kind)};
  struct Range {
    double lo, hi;
    const char* what;
  };
  const Range feature = [&]() -> Range {
    switch (*kind) {
      case ArtifactKind::coin:
        return {4.0, 64.0, "reeds"};
      case ArtifactKind::tablet:
        return {0.004, 0.03, "groove spacing [m]"};
      default:
        return {0.0, 0.01, "feature height [m]"};
    }
  }();
  const auto outside = [](double v, double lo, double hi) { return !(v >= lo && v <= hi); };
  if (outside(form.feature, feature.lo, feature.hi))
    return Error{fmt::format("the {}'s {} {} is not within {}..{}", form.kind, feature.what, form.feature,
                             feature.lo, feature.hi)};
  if (outside(form.stiffness, 1e3, 1e7))
    return Error{
        fmt::format("the {}'s stiffness {} N/m^2 is not within 1e3..1e7", form.kind, form.stiffness)};
  if (outside(form.friction_static, 0.0, 2.0) || outside(form.friction_dynamic, 0.0, 2.0))
    return Error{fmt::format("the {}'s friction {} / {} is not within 0..2", form.kind, form.friction_static,
                             form.friction_dynamic)};
  return *kind;
}

Result<collette::TriangleMesh> artifact_mesh(const museum::PieceForm& form) {
  const auto kind = check_form(form);
  if (!kind) return kind.error();
  return mesh_of(*kind, form);
}

collette::TriangleMesh artifact_mesh(ArtifactKind kind, Difficulty difficulty, Piece piece) {
  return mesh_of(kind, piece_form(kind, difficulty, piece));
}

Result<controllers::SceneShape> artifact_shape(const museum::PieceForm& form,
                                               const std::filesystem::path& cache_dir, std::int64_t spheres) {
  auto mesh = artifact_mesh(form);
  if (!mesh) return mesh.error();
  const std::string obj = collette::obj_text(
      *mesh, fmt::format("{}: a museum artifact generated by UnrealHaptics (metres)", mesh->source_name));
  const std::uint64_t hash = collette::ist_hash_bytes(std::as_bytes(std::span<const char>(obj)));
  const auto path = cache_dir / "museum-artifacts" /
                    fmt::format("{}-{}-{:016x}.obj", form.kind, museum::to_string(form.difficulty), hash);
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec)
      return Error{
          fmt::format("{}: cannot create the folder: {}", path.parent_path().string(), ec.message())};
    if (auto written = write_file_atomically(path, obj); !written) return written.error();
  }
  return controllers::SceneShape{.mesh = path, .spheres = spheres, .meters_per_unit = 1.0};
}

Result<controllers::SceneShape> artifact_shape(ArtifactKind kind, Difficulty difficulty, Piece piece,
                                               const std::filesystem::path& cache_dir, std::int64_t spheres) {
  return artifact_shape(piece_form(kind, difficulty, piece), cache_dir, spheres);
}

Result<controllers::SceneObject> artifact_object(const museum::PieceForm& form,
                                                 const std::filesystem::path& cache_dir,
                                                 const std::string& name, const Pose& pose,
                                                 std::int64_t spheres) {
  auto shape = artifact_shape(form, cache_dir, spheres);
  if (!shape) return shape.error();
  return controllers::SceneObject{
      .name = name,
      .shape = *shape,
      .pose = pose,
      .material = surface_material(form.stiffness, form.friction_static, form.friction_dynamic)};
}

Result<controllers::SceneObject> artifact_object(ArtifactKind kind, Difficulty difficulty, Piece piece,
                                                 const std::filesystem::path& cache_dir,
                                                 const std::string& name, const Pose& pose,
                                                 std::int64_t spheres) {
  return artifact_object(piece_form(kind, difficulty, piece), cache_dir, name, pose, spheres);
}

controllers::Scene table_scene(const controllers::SceneObject& piece,
                               std::shared_ptr<const collette::SphereTree> tool, double haptic_hz) {
  controllers::Scene scene;
  scene.name = "museum table";
  scene.source = "Phantom's table";
  scene.objects = {piece};
  scene.tool().name = "stylus";
  scene.tool().shape.tree = std::move(tool);
  scene.tool().shape.coverage = 1.0;
  scene.watch = {piece.name};
  scene.haptic_hz = haptic_hz;
  scene.collision_hz = haptic_hz;
  scene.force.proxy.enabled = true;
  return scene;
}

}  // namespace uh::museum_artifacts
