#pragma once
// Test helpers for the mesh and packing tests: small meshes written to a temporary directory and
// brute-force reference geometry, written independently of the library's BVH code.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/math.hpp"

namespace uh::collette::test {

using Tri = std::array<std::int32_t, 3>;

/// A fresh directory under the system temp dir, removed when the object goes away.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    path_ = std::filesystem::temp_directory_path() /
            ("uh_mesh_test_" + tag + "_" + std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// Unit cube [0,1]^3, 8 vertices, 12 triangles wound counter-clockwise from outside.
inline TriangleMesh unit_cube() {
  TriangleMesh m;
  m.source_name = "cube";
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  return m;
}

/// Icosphere of the given radius: an icosahedron subdivided `levels` times, projected outwards.
inline TriangleMesh icosphere(double radius, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Tri> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                        {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                        {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (Vec3& p : v) p = normalized(p);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> mid;
    auto midpoint = [&](std::int32_t a, std::int32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(normalized((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]) * 0.5));
      const auto id = static_cast<std::int32_t>(v.size() - 1);
      mid.emplace(key, id);
      return id;
    };
    std::vector<Tri> g;
    for (const Tri& tri : f) {
      const std::int32_t ab = midpoint(tri[0], tri[1]);
      const std::int32_t bc = midpoint(tri[1], tri[2]);
      const std::int32_t ca = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], ab, ca});
      g.push_back({tri[1], bc, ab});
      g.push_back({tri[2], ca, bc});
      g.push_back({ab, bc, ca});
    }
    f = std::move(g);
  }
  TriangleMesh m;
  m.source_name = "icosphere";
  for (const Vec3& p : v) m.vertices.push_back(p * radius);
  m.triangles = f;
  return m;
}

/// Torus around the z axis: major radius R, minor radius r, n x m quads split into triangles.
inline TriangleMesh torus(double major, double minor, int n, int m) {
  TriangleMesh mesh;
  mesh.source_name = "torus";
  for (int i = 0; i < n; ++i) {
    const double u = 2.0 * kPi * i / n;
    for (int j = 0; j < m; ++j) {
      const double w = 2.0 * kPi * j / m;
      mesh.vertices.push_back({(major + minor * std::cos(w)) * std::cos(u), (major + minor * std::cos(w)) * std::sin(u),
                               minor * std::sin(w)});
    }
  }
  auto id = [&](int i, int j) { return static_cast<std::int32_t>(((i + n) % n) * m + (j + m) % m); };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return mesh;
}

inline void write_obj(const std::filesystem::path& p, const std::vector<Vec3>& v, const std::vector<Tri>& f) {
  std::ofstream out(p);
  out.precision(17);
  for (const Vec3& x : v) out << "v " << x.x << ' ' << x.y << ' ' << x.z << '\n';
  for (const Tri& t : f) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

inline void write_off(const std::filesystem::path& p, const std::vector<Vec3>& v, const std::vector<Tri>& f) {
  std::ofstream out(p);
  out.precision(17);
  out << "OFF\n" << v.size() << ' ' << f.size() << " 0\n";
  for (const Vec3& x : v) out << x.x << ' ' << x.y << ' ' << x.z << '\n';
  for (const Tri& t : f) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

/// ASCII STL: every facet repeats its corners, as real STL files do.
inline void write_stl(const std::filesystem::path& p, const std::vector<Vec3>& v, const std::vector<Tri>& f) {
  std::ofstream out(p);
  out.precision(17);
  out << "solid test\n";
  for (const Tri& t : f) {
    const Vec3& a = v[static_cast<std::size_t>(t[0])];
    const Vec3& b = v[static_cast<std::size_t>(t[1])];
    const Vec3& c = v[static_cast<std::size_t>(t[2])];
    const Vec3 n = normalized(cross(b - a, c - a));
    out << " facet normal " << n.x << ' ' << n.y << ' ' << n.z << "\n  outer loop\n";
    for (const Vec3* x : {&a, &b, &c}) out << "   vertex " << x->x << ' ' << x->y << ' ' << x->z << '\n';
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid test\n";
}

/// Distance from p to the segment ab.
inline double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = squared_norm(ab);
  const double t = len2 > 0.0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return norm(p - (a + ab * t));
}

/// Reference point-triangle distance: the plane distance when p projects inside the triangle,
/// otherwise the nearest of the three edges (a different method from the library's).
inline double triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = cross(b - a, c - a);
  const double n2 = squared_norm(n);
  if (n2 > 0.0) {
    const double s = dot(p - a, n) / n2;
    const Vec3 q = p - n * s;
    const bool in = dot(cross(b - a, q - a), n) >= 0.0 && dot(cross(c - b, q - b), n) >= 0.0 &&
                    dot(cross(a - c, q - c), n) >= 0.0;
    if (in) return std::abs(s) * std::sqrt(n2);
  }
  return std::min({segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

inline double brute_distance(const TriangleMesh& m, const Vec3& p) {
  double best = 1e300;
  for (const Tri& t : m.triangles) {
    best = std::min(best, triangle_distance(p, m.vertices[static_cast<std::size_t>(t[0])],
                                            m.vertices[static_cast<std::size_t>(t[1])], m.vertices[static_cast<std::size_t>(t[2])]));
  }
  return best;
}

/// Reference generalised winding number: the sum of signed solid angles over all triangles / 4 pi.
inline double brute_winding(const TriangleMesh& m, const Vec3& p) {
  double w = 0.0;
  for (const Tri& t : m.triangles) {
    const Vec3 a = m.vertices[static_cast<std::size_t>(t[0])] - p;
    const Vec3 b = m.vertices[static_cast<std::size_t>(t[1])] - p;
    const Vec3 c = m.vertices[static_cast<std::size_t>(t[2])] - p;
    const double la = norm(a), lb = norm(b), lc = norm(c);
    w += 2.0 * std::atan2(dot(a, cross(b, c)), la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb);
  }
  return w / (4.0 * kPi);
}

}  // namespace uh::collette::test
