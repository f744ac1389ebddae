// Writes a small seed corpus for ist_loader_fuzz into the directory given as argv[1]: valid .ist
// images of a few generated sphere sets (1, 2, 9 and ~100 leaves, arity 2, 4 and 8), each once in
// format 1 and, at arity 4, once in format 2 with a surface (the box around the spheres).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "uh/collette/ist_file.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

namespace {

// the box around `leaves` (a margin of 0.1 beyond them), wound outward
uh::collette::TriangleMesh box_around(const std::vector<uh::Sphere>& leaves) {
  uh::Vec3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
  for (const uh::Sphere& s : leaves) {
    const double r = static_cast<double>(s.radius) + 0.1;
    lo = {std::min(lo.x, static_cast<double>(s.x) - r), std::min(lo.y, static_cast<double>(s.y) - r),
          std::min(lo.z, static_cast<double>(s.z) - r)};
    hi = {std::max(hi.x, static_cast<double>(s.x) + r), std::max(hi.y, static_cast<double>(s.y) + r),
          std::max(hi.z, static_cast<double>(s.z) + r)};
  }
  uh::collette::TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <corpus directory>\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  int written = 0;
  for (int n : {1, 2, 9, 100}) {
    std::vector<uh::Sphere> leaves;
    // spheres on a line of spacing 1 and a spiral, radius below half the spacing: disjoint
    for (int i = 0; i < n; ++i) {
      const float t = static_cast<float>(i);
      leaves.push_back({t, std::sin(t), std::cos(t), 0.3f + 0.1f * std::sin(3.f * t)});
    }
    for (int arity : {2, 4, 8}) {
      for (const bool surface : {false, true}) {
        if (surface && arity != 4) continue;
        auto tree = uh::collette::build_sphere_tree(leaves, {.arity = arity});
        if (!tree) {
          std::fprintf(stderr, "%s\n", tree.error().message.c_str());
          return 1;
        }
        uh::collette::IstAsset asset{std::move(*tree), {}};
        asset.meta.coverage = 0.8;
        asset.meta.mesh_volume = asset.tree.total_volume() / 0.8;
        if (surface) {
          asset.surface = box_around(leaves);
          asset.meta.mesh_volume = uh::collette::mesh_volume(*asset.surface);
          asset.meta.coverage = asset.tree.total_volume() / asset.meta.mesh_volume;
        }
        if (const uh::Status ok = uh::collette::validate(asset); !ok) {
          std::fprintf(stderr, "seed %d/%d: %s\n", n, arity, ok.error().message.c_str());
          return 1;
        }
        const auto bytes = uh::collette::encode_ist(asset);
        const std::string name =
            "seed_" + std::to_string(n) + "_" + std::to_string(arity) + (surface ? "_surface" : "") + ".ist";
        std::ofstream out(dir / name, std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
        ++written;
      }
    }
  }
  std::printf("%d seeds in %s\n", written, dir.c_str());
  return 0;
}
