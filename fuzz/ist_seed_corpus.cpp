// Writes a small seed corpus for ist_loader_fuzz into the directory given as argv[1]: valid .ist
// images of a few generated sphere sets (1, 2, 9 and ~100 leaves, arity 2, 4 and 8).

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "uh/collette/ist_file.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

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
      auto tree = uh::collette::build_sphere_tree(leaves, {.arity = arity});
      if (!tree) {
        std::fprintf(stderr, "%s\n", tree.error().message.c_str());
        return 1;
      }
      uh::collette::IstAsset asset{std::move(*tree), {}};
      asset.meta.coverage = 0.8;
      asset.meta.mesh_volume = asset.tree.total_volume() / 0.8;
      if (const uh::Status ok = uh::collette::validate(asset); !ok) {
        std::fprintf(stderr, "seed %d/%d: %s\n", n, arity, ok.error().message.c_str());
        return 1;
      }
      const auto bytes = uh::collette::encode_ist(asset);
      std::ofstream out(dir / ("seed_" + std::to_string(n) + "_" + std::to_string(arity) + ".ist"),
                        std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      ++written;
    }
  }
  std::printf("%d seeds in %s\n", written, dir.c_str());
  return 0;
}
