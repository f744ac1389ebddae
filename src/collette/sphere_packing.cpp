#include "uh/collette/sphere_packing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "sphere_grid.hpp"
#include "triangle_bvh.hpp"

namespace uh::collette {
namespace {

// Automatic voxel size: cbrt(volume / target) times this. Smaller gives better coverage and
// costs time and memory roughly as its inverse cube (measured in docs/collette-packing.md).
constexpr double kAutoVoxelFactor = 0.18;
constexpr std::int64_t kMaxGridVoxels = 400'000'000;
constexpr std::int64_t kDefaultAutoCount = 10000;
// Spheres smaller than this fraction of a voxel are not placed: the grid cannot resolve them.
constexpr double kMinRadiusInVoxels = 0.05;
// Centre refinement: tries per sphere, first step in voxels, and how far (as a fraction of the
// voxel's surface distance) a centre may wander, which keeps it inside the mesh. More tries or
// longer steps did not raise coverage on the 69k bunny.
constexpr int kRefineIterations = 24;
constexpr double kFirstStep = 0.5;
constexpr double kLeash = 0.5;
// Queue resolution: buckets per voxel edge.
constexpr double kBucketsPerVoxel = 32.0;
// Raster sweeps propagating nearest surface points inwards (forward, backward); more passes
// tighten the upper bounds but the exact check at use time makes that unnecessary.
constexpr int kSweepPasses = 2;

// Max-priority queue of voxel ids keyed by free radius, quantised into buckets of 1/delta:
// O(1) push and pop instead of a binary heap's cache-missing sifts over a million entries.
// Within a bucket the order is last in, first out, so the result stays deterministic; the
// greedy choice is then "largest up to 1/kBucketsPerVoxel of a voxel".
class BucketQueue {
 public:
  explicit BucketQueue(double buckets_per_length) : scale_(buckets_per_length) {}
  std::int64_t bucket_of(float key) const {
    const double b = std::floor(static_cast<double>(key) * scale_);
    return b > 0.0 ? static_cast<std::int64_t>(b) : 0;
  }
  double upper_bound(std::int64_t bucket) const { return static_cast<double>(bucket + 1) / scale_; }
  void push(float key, std::int32_t id) {
    const std::int64_t b = bucket_of(key);
    if (b >= static_cast<std::int64_t>(buckets_.size())) buckets_.resize(static_cast<std::size_t>(b) + 1);
    buckets_[static_cast<std::size_t>(b)].push_back(id);
    top_ = std::max(top_, b);
  }
  bool pop(std::int32_t& id, std::int64_t& bucket) {
    while (top_ >= 0 && buckets_[static_cast<std::size_t>(top_)].empty()) --top_;
    if (top_ < 0) return false;
    auto& b = buckets_[static_cast<std::size_t>(top_)];
    id = b.back();
    b.pop_back();
    bucket = top_;
    return true;
  }

 private:
  double scale_;
  std::vector<std::vector<std::int32_t>> buckets_;
  std::int64_t top_ = -1;
};

class Progress {
 public:
  explicit Progress(const std::function<void(double)>& fn) : fn_(fn) {}
  void report(double f) {
    if (!fn_) return;
    f = std::clamp(f, 0.0, 1.0);
    // at most about 200 calls: the callback may draw a progress bar
    if (f < last_ + 0.005 && f < 1.0) return;
    if (f <= last_ && last_ >= 0.0) return;
    last_ = f;
    fn_(f);
  }

 private:
  const std::function<void(double)>& fn_;
  double last_ = -1.0;
};

Vec3 to_vec(const Sphere& s) { return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)}; }


// deterministic points on a triangle: the centroid, then a 2D low-discrepancy sequence folded in
Vec3 triangle_sample(const detail::Triangle& t, int s) {
  if (s == 0) return (t.a + t.b + t.c) / 3.0;
  double u = std::fmod(0.5 + 0.7548776662466927 * s, 1.0);
  double v = std::fmod(0.5 + 0.5698402909980532 * s, 1.0);
  if (u + v > 1.0) {
    u = 1.0 - u;
    v = 1.0 - v;
  }
  return t.a + (t.b - t.a) * u + (t.c - t.a) * v;
}

// Closes each hole of an open mesh with a fan around the hole's centroid, wound against the
// boundary so that the result is consistently oriented. This is the assumption pack_spheres
// makes for meshes accepted with allow_open: holes are spanned by (nearly) flat caps.
TriangleMesh cap_holes(const TriangleMesh& mesh) {
  TriangleMesh out = mesh;
  std::vector<std::pair<std::uint64_t, std::int32_t>> undirected;  // (edge key, source vertex)
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      const std::int32_t a = t[static_cast<std::size_t>(e)];
      const std::int32_t b = t[static_cast<std::size_t>((e + 1) % 3)];
      const auto lo = static_cast<std::uint64_t>(std::min(a, b));
      const auto hi = static_cast<std::uint64_t>(std::max(a, b));
      undirected.emplace_back((lo << 32) | hi, a);
    }
  }
  std::sort(undirected.begin(), undirected.end());
  // boundary edges as directed a -> b, sorted by a for lookup
  std::vector<std::pair<std::int32_t, std::int32_t>> next;
  for (std::size_t i = 0; i < undirected.size();) {
    std::size_t j = i;
    while (j < undirected.size() && undirected[j].first == undirected[i].first) ++j;
    if (j - i == 1) {
      const auto lo = static_cast<std::int32_t>(undirected[i].first >> 32);
      const auto hi = static_cast<std::int32_t>(undirected[i].first & 0xffffffffULL);
      const std::int32_t a = undirected[i].second;
      next.emplace_back(a, a == lo ? hi : lo);
    }
    i = j;
  }
  std::sort(next.begin(), next.end());
  std::vector<char> used(next.size(), 0);
  for (std::size_t start = 0; start < next.size(); ++start) {
    if (used[start] != 0) continue;
    std::vector<std::int32_t> loop;
    std::size_t e = start;
    while (used[e] == 0) {
      used[e] = 1;
      loop.push_back(next[e].first);
      const std::int32_t to = next[e].second;
      auto it = std::lower_bound(next.begin(), next.end(), std::make_pair(to, std::numeric_limits<std::int32_t>::min()));
      while (it != next.end() && it->first == to && used[static_cast<std::size_t>(it - next.begin())] != 0) ++it;
      if (it == next.end() || it->first != to) break;
      e = static_cast<std::size_t>(it - next.begin());
    }
    if (loop.size() < 3) continue;
    Vec3 c{};
    for (const std::int32_t v : loop) c += mesh.vertices[static_cast<std::size_t>(v)];
    out.vertices.push_back(c / static_cast<double>(loop.size()));
    const auto ci = static_cast<std::int32_t>(out.vertices.size() - 1);
    for (std::size_t i = 0; i < loop.size(); ++i) out.triangles.push_back({ci, loop[(i + 1) % loop.size()], loop[i]});
  }
  out.report.assumed_open = false;
  return out;
}

}  // namespace

double measure_max_gap(const TriangleMesh& mesh, const std::vector<Sphere>& spheres, int samples_per_triangle) {
  if (spheres.empty() || mesh.vertices.empty()) return std::numeric_limits<double>::infinity();
  const Aabb box = mesh_bounds(mesh);
  const double diag = norm(box.max - box.min);
  // cell size near the typical small sphere: about 64 cells along the diagonal
  double cell = diag / 64.0;
  std::vector<float> radii;
  radii.reserve(spheres.size());
  for (const Sphere& s : spheres) radii.push_back(s.radius);
  std::nth_element(radii.begin(), radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2), radii.end());
  cell = std::clamp(4.0 * static_cast<double>(radii[radii.size() / 2]), diag / 512.0, diag / 16.0);
  detail::SphereGrid grid(box.min, box.max, cell);
  for (std::size_t i = 0; i < spheres.size(); ++i) grid.insert(spheres[i], static_cast<std::int32_t>(i));
  double gap = 0.0;
  for (const Vec3& v : mesh.vertices) gap = std::max(gap, grid.distance_to_union(v));
  for (const auto& tri : mesh.triangles) {
    const detail::Triangle t{mesh.vertices[static_cast<std::size_t>(tri[0])], mesh.vertices[static_cast<std::size_t>(tri[1])],
                             mesh.vertices[static_cast<std::size_t>(tri[2])]};
    for (int s = 0; s < samples_per_triangle; ++s) gap = std::max(gap, grid.distance_to_union(triangle_sample(t, s)));
  }
  return gap;
}

namespace {

Status check_mesh_to_pack(const TriangleMesh& mesh) {
  const std::string& name = mesh.source_name;
  if (mesh.triangles.empty()) return Error{fmt::format("{}: cannot pack spheres into an empty mesh", name)};
  if (!mesh.report.closed_manifold() && !mesh.report.assumed_open) {
    return Error{fmt::format("{}: cannot pack spheres: the mesh is not closed and 2-manifold (validate it first)", name)};
  }
  return Ok{};
}

Status check_packing_options(const std::string& name, const PackingOptions& options) {
  if (options.target_sphere_count < 0 || options.voxel_size < 0.0 || !std::isfinite(options.voxel_size)) {
    return Error{fmt::format("{}: invalid packing options (negative sphere count or voxel size)", name)};
  }
  if (!(options.max_radius >= 0.0 && std::isfinite(options.max_radius))) {
    return Error{fmt::format("{}: invalid packing options (the largest sphere radius must be >= 0, got {})",
                             name, options.max_radius)};
  }
  return Ok{};
}

// The voxel grid around the mesh, one voxel beyond its bounds on every side: cell (i, j, k) is
// number i + nx (j + ny k), its centre origin + (i + 1/2, j + 1/2, k + 1/2) h.
struct VoxelGrid {
  Aabb bounds{};
  Vec3 origin{};
  double h = 0.0;
  std::int64_t nx = 0, ny = 0, nz = 0;

  std::int64_t size() const { return nx * ny * nz; }
  std::int64_t cell(std::int64_t i, std::int64_t j, std::int64_t k) const { return i + nx * (j + ny * k); }
  Vec3 centre(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return Vec3{origin.x + (static_cast<double>(i) + 0.5) * h, origin.y + (static_cast<double>(j) + 0.5) * h,
                origin.z + (static_cast<double>(k) + 0.5) * h};
  }
  Vec3 centre(std::int64_t g) const { return centre(g % nx, (g / nx) % ny, g / (nx * ny)); }
  double diagonal() const { return norm(bounds.max - bounds.min); }
};

// The grid at the options' voxel size (automatic: from the volume per sphere), or why it is too large.
Result<VoxelGrid> make_voxel_grid(const TriangleMesh& mesh, double volume, const PackingOptions& options) {
  const std::int64_t target = options.target_sphere_count;
  VoxelGrid grid;
  grid.h = options.voxel_size;
  if (grid.h == 0.0) {
    const auto n = static_cast<double>(target > 0 ? target : kDefaultAutoCount);
    grid.h = std::cbrt(volume / n) * kAutoVoxelFactor;
  }
  const double h = grid.h;
  grid.bounds = mesh_bounds(mesh);
  grid.origin = grid.bounds.min - Vec3{h, h, h};
  const Vec3 ext = grid.bounds.max - grid.bounds.min;
  grid.nx = static_cast<std::int64_t>(std::ceil(ext.x / h)) + 2;
  grid.ny = static_cast<std::int64_t>(std::ceil(ext.y / h)) + 2;
  grid.nz = static_cast<std::int64_t>(std::ceil(ext.z / h)) + 2;
  if (static_cast<double>(grid.nx) * static_cast<double>(grid.ny) * static_cast<double>(grid.nz) >
      static_cast<double>(kMaxGridVoxels)) {
    return Error{fmt::format("{}: voxel size {} needs a {}x{}x{} grid, more than {} voxels; use a larger voxel size",
                             mesh.source_name, h, grid.nx, grid.ny, grid.nz, kMaxGridVoxels)};
  }
  return grid;
}

// The voxels whose centre is inside the mesh, numbered in grid order.
struct Interior {
  std::vector<std::int32_t> id_of_cell;  // -1 outside
  std::vector<std::int64_t> cell_of_id;
  std::int64_t count() const { return static_cast<std::int64_t>(cell_of_id.size()); }
};

// Classifies row (j, k) from one ray along +x whose crossings `hits` returned sorted: the winding
// number at a voxel is minus the sum of the crossing signs before it (the ray starts outside).
// Winding instead of parity keeps interpenetrating closed shells inside. A row whose ray grazes an
// edge or vertex (signs not summing to zero, coincident crossings) falls back to a three-ray vote
// per voxel.
void classify_row(const VoxelGrid& grid, const detail::TriangleBvh& bvh, std::int64_t j, std::int64_t k,
                  const std::vector<std::pair<double, int>>& hits, Interior& interior) {
  int total = 0;
  for (const auto& hit : hits) total += hit.second;
  bool suspicious = total != 0;
  const double coincident = 1e-9 * grid.diagonal();
  for (std::size_t q = 1; q < hits.size() && !suspicious; ++q) {
    suspicious = (hits[q].first - hits[q - 1].first) < coincident;
  }
  std::size_t next_hit = 0;
  int winding = 0;
  for (std::int64_t i = 0; i < grid.nx; ++i) {
    const double t = (static_cast<double>(i) + 0.5) * grid.h + grid.h;
    bool inside;
    if (suspicious) {
      inside = bvh.inside_vote(grid.centre(i, j, k));
    } else {
      while (next_hit < hits.size() && hits[next_hit].first < t) winding -= hits[next_hit++].second;
      inside = winding > 0;
    }
    if (inside) {
      const std::int64_t g = grid.cell(i, j, k);
      interior.id_of_cell[static_cast<std::size_t>(g)] = static_cast<std::int32_t>(interior.cell_of_id.size());
      interior.cell_of_id.push_back(g);
    }
  }
}

// Stage 1 (progress 0 to 0.1): the interior voxels, row by row.
Interior classify_voxels(const VoxelGrid& grid, const detail::TriangleBvh& bvh, Progress& progress) {
  Interior interior;
  interior.id_of_cell.assign(static_cast<std::size_t>(grid.size()), -1);
  std::vector<std::pair<double, int>> hits;
  for (std::int64_t k = 0; k < grid.nz; ++k) {
    for (std::int64_t j = 0; j < grid.ny; ++j) {
      const Vec3 o{grid.origin.x - grid.h, grid.origin.y + (static_cast<double>(j) + 0.5) * grid.h,
                   grid.origin.z + (static_cast<double>(k) + 0.5) * grid.h};
      hits.clear();
      bvh.ray_hits(o, {1.0, 0.0, 0.0}, std::numeric_limits<double>::infinity(), hits);
      if (hits.empty()) continue;
      std::sort(hits.begin(), hits.end());
      classify_row(grid, bvh, j, k, hits, interior);
    }
    progress.report(0.1 * static_cast<double>(k + 1) / static_cast<double>(grid.nz));
  }
  return interior;
}

// Distances from the interior voxels to the surface, with the surface point each was measured to.
struct SurfaceDistances {
  std::vector<float> distance;
  std::vector<Vec3> nearest;
};

constexpr float kInf = std::numeric_limits<float>::infinity();

// Exact distances of the interior voxels around triangle `t` (those within its box and 1.5
// voxels beyond), where nearer than what is known.
void measure_near_triangle(const detail::Triangle& t, const VoxelGrid& grid, const Interior& interior,
                           SurfaceDistances& out) {
  const double h = grid.h;
  const Vec3 lo{std::min({t.a.x, t.b.x, t.c.x}), std::min({t.a.y, t.b.y, t.c.y}), std::min({t.a.z, t.b.z, t.c.z})};
  const Vec3 hi{std::max({t.a.x, t.b.x, t.c.x}), std::max({t.a.y, t.b.y, t.c.y}), std::max({t.a.z, t.b.z, t.c.z})};
  auto cell_lo = [&](double v, double o) { return static_cast<std::int64_t>(std::floor((v - o) / h - 1.5)); };
  auto cell_hi = [&](double v, double o) { return static_cast<std::int64_t>(std::ceil((v - o) / h + 0.5)); };
  const std::int64_t i0 = std::max<std::int64_t>(0, cell_lo(lo.x, grid.origin.x)), i1 = std::min(grid.nx - 1, cell_hi(hi.x, grid.origin.x));
  const std::int64_t j0 = std::max<std::int64_t>(0, cell_lo(lo.y, grid.origin.y)), j1 = std::min(grid.ny - 1, cell_hi(hi.y, grid.origin.y));
  const std::int64_t k0 = std::max<std::int64_t>(0, cell_lo(lo.z, grid.origin.z)), k1 = std::min(grid.nz - 1, cell_hi(hi.z, grid.origin.z));
  for (std::int64_t k = k0; k <= k1; ++k) {
    for (std::int64_t j = j0; j <= j1; ++j) {
      for (std::int64_t i = i0; i <= i1; ++i) {
        const std::int32_t id = interior.id_of_cell[static_cast<std::size_t>(grid.cell(i, j, k))];
        if (id < 0) continue;
        const Vec3 p = grid.centre(i, j, k);
        // the triangle is no nearer than its box: most visits after the first few triangles
        // around a voxel end here, with the same result as the exact test below
        const double bx = std::max({lo.x - p.x, 0.0, p.x - hi.x});
        const double by = std::max({lo.y - p.y, 0.0, p.y - hi.y});
        const double bz = std::max({lo.z - p.z, 0.0, p.z - hi.z});
        float& known = out.distance[static_cast<std::size_t>(id)];
        if (bx * bx + by * by + bz * bz >= static_cast<double>(known) * static_cast<double>(known)) continue;
        const Vec3 q = detail::closest_point_on_triangle(p, t);
        const auto d = static_cast<float>(norm(q - p));
        if (d < known) {
          known = d;
          out.nearest[static_cast<std::size_t>(id)] = q;
        }
      }
    }
  }
}

// Passes nearest surface points inwards between neighbours: two raster sweeps (forward over the 13
// earlier neighbours, backward over the 13 later). Progress 0.15 to 0.2.
void sweep_inwards(const VoxelGrid& grid, const Interior& interior, SurfaceDistances& out, Progress& progress) {
  std::int64_t offsets[13];
  int n_off = 0;
  for (std::int64_t dk = -1; dk <= 0; ++dk) {
    for (std::int64_t dj = -1; dj <= 1; ++dj) {
      for (std::int64_t di = -1; di <= 1; ++di) {
        const std::int64_t off = grid.cell(di, dj, dk);
        if (off < 0) offsets[n_off++] = off;
      }
    }
  }
  const std::int64_t n_interior = interior.count();
  for (int pass = 0; pass < kSweepPasses; ++pass) {
    const bool forward = pass % 2 == 0;
    for (std::int64_t q = 0; q < n_interior; ++q) {
      const std::int64_t idx = forward ? q : n_interior - 1 - q;
      const std::int64_t g = interior.cell_of_id[static_cast<std::size_t>(idx)];
      const Vec3 p = grid.centre(g);
      float& d = out.distance[static_cast<std::size_t>(idx)];
      for (int o = 0; o < n_off; ++o) {
        const std::int64_t gn = g + (forward ? offsets[o] : -offsets[o]);
        if (gn < 0 || gn >= grid.size()) continue;
        const std::int32_t nb = interior.id_of_cell[static_cast<std::size_t>(gn)];
        if (nb < 0 || out.distance[static_cast<std::size_t>(nb)] == kInf) continue;
        const Vec3& cand = out.nearest[static_cast<std::size_t>(nb)];
        const auto dc = static_cast<float>(norm(cand - p));
        if (dc < d) {
          d = dc;
          out.nearest[static_cast<std::size_t>(idx)] = cand;
        }
      }
    }
    progress.report(0.15 + 0.05 * (pass + 1) / kSweepPasses);
  }
}

// Stage 2 (progress 0.1 to 0.2): distance to the surface for interior voxels: exact near the
// surface (every triangle visits the voxels around it), then propagated inwards. Propagated values
// are distances to real surface points, so they are upper bounds; the packing replaces them with
// exact BVH distances before using them.
std::vector<float> surface_distances(const TriangleMesh& solid, const VoxelGrid& grid, const Interior& interior,
                                     Progress& progress) {
  SurfaceDistances out{std::vector<float>(static_cast<std::size_t>(interior.count()), kInf),
                       std::vector<Vec3>(static_cast<std::size_t>(interior.count()))};
  for (const auto& tri : solid.triangles) {
    const detail::Triangle t{solid.vertices[static_cast<std::size_t>(tri[0])], solid.vertices[static_cast<std::size_t>(tri[1])],
                             solid.vertices[static_cast<std::size_t>(tri[2])]};
    measure_near_triangle(t, grid, interior, out);
  }
  progress.report(0.15);
  sweep_inwards(grid, interior, out, progress);
  for (float& d : out.distance) {
    if (d == kInf) d = static_cast<float>(grid.diagonal());  // unreachable in practice; still an upper bound
  }
  return std::move(out.distance);
}

// Stage 3 (progress 0.2 to 0.95): greedy largest-free-sphere placement. Queue entries are upper
// bounds of a voxel's current free radius (it only decreases); a popped entry that turns out
// smaller is pushed back.
class GreedyPacker {
 public:
  GreedyPacker(const VoxelGrid& grid, const detail::TriangleBvh& bvh, const Interior& interior,
               std::vector<float> surface_distance, const PackingOptions& options, Progress& progress)
      : grid_(grid),
        bvh_(bvh),
        interior_(interior),
        options_(options),
        progress_(progress),
        dsurf_(std::move(surface_distance)),
        fsph_(dsurf_.size(), kInf),
        exact_(dsurf_.size(), 0),
        removed_(dsurf_.size(), 0),
        queue_(kBucketsPerVoxel / grid.h),
        min_radius_(kMinRadiusInVoxels * grid.h),
        margin_(options.safety_margin * grid.h),
        max_radius_(options.max_radius > 0.0 ? options.max_radius : std::numeric_limits<double>::infinity()),
        sgrid_(grid.bounds.min, grid.bounds.max, 2.0 * grid.h) {
    for (std::int64_t q = 0; q < interior_.count(); ++q)
      queue_.push(radius_bound_f(dsurf_[static_cast<std::size_t>(q)]), static_cast<std::int32_t>(q));
  }

  std::vector<Sphere> run() {
    const std::int64_t target = options_.target_sphere_count;
    std::int32_t id = -1;
    std::int64_t bucket = 0;
    while ((target == 0 || static_cast<std::int64_t>(spheres_.size()) < target) && queue_.pop(id, bucket)) {
      if (!ready_to_place(id, bucket)) continue;
      // every live voxel's free radius is below the top of this bucket
      const auto key = static_cast<float>(queue_.upper_bound(bucket));
      if (!place_at(static_cast<std::size_t>(id), key)) continue;
      if (target > 0) {
        progress_.report(0.2 + 0.75 * static_cast<double>(spheres_.size()) / static_cast<double>(target));
      } else {
        progress_.report(0.2 + 0.75 * static_cast<double>(removed_count_) /
                                   static_cast<double>(interior_.count()));
      }
    }
    return std::move(spheres_);
  }

 private:
  // The largest radius a sphere centred `d` from the surface may have. Monotone in d, so an upper
  // bound of d still gives an upper bound of the radius (the queue's invariant).
  double radius_bound(double d) const { return std::min(d, max_radius_); }
  float radius_bound_f(float d) const { return static_cast<float>(radius_bound(static_cast<double>(d))); }

  void remove(std::size_t uid) {
    removed_[uid] = 1;
    ++removed_count_;
  }

  // Whether popped voxel `id` is still live and its free radius still in `bucket`; a voxel too
  // small is removed, one whose radius fell is pushed back where it belongs. Its surface distance
  // is made exact the first time it gets here.
  bool ready_to_place(std::int32_t id, std::int64_t bucket) {
    const auto uid = static_cast<std::size_t>(id);
    if (removed_[uid] != 0) return false;
    const float current = std::min(radius_bound_f(dsurf_[uid]), fsph_[uid]);
    if (static_cast<double>(current) <= min_radius_) {
      remove(uid);
      return false;
    }
    if (queue_.bucket_of(current) < bucket) {
      queue_.push(current, id);
      return false;
    }
    if (exact_[uid] != 0) return true;
    exact_[uid] = 1;
    const auto d = static_cast<float>(std::sqrt(bvh_.closest(grid_.centre(interior_.cell_of_id[uid]))));
    if (d < dsurf_[uid]) {
      dsurf_[uid] = d;
      const float bound = std::min(radius_bound_f(d), fsph_[uid]);
      if (queue_.bucket_of(bound) < bucket) {
        queue_.push(bound, id);
        return false;
      }
    }
    return true;
  }

  // Free radius at p: exact distance to the surface and to the placed spheres within `reach`
  // (never more than the largest radius allowed); `away`, if given, the direction away from the
  // nearest of them.
  double free_at(const Vec3& p, double reach, Vec3* away) const {
    Vec3 qs{};
    const double ds = radius_bound(std::sqrt(bvh_.closest(p, &qs, reach * reach)));
    std::int32_t nid = -1;
    const double dsp = sgrid_.free_radius(p, std::min(ds, reach), &nid);
    if (away != nullptr) {
      if (nid >= 0 && dsp < ds) {
        *away = normalized(p - to_vec(spheres_[static_cast<std::size_t>(nid)]));
      } else {
        *away = ds < reach ? normalized(p - qs) : Vec3{};
      }
    }
    return std::min(ds, dsp);
  }

  // ProtoSphere-style refinement: step away from the nearest obstacle while the free radius grows,
  // halving the step when it does not; stay within `leash` of the voxel centre `v` so the centre
  // cannot leave the mesh. The free radius is 1-Lipschitz, so every evaluation is bounded by the
  // best value so far plus the step: searching further would only cost time.
  void refine_centre(const Vec3& v, double leash, double slack, Vec3& p, Vec3& away, double& best) const {
    double step = kFirstStep * grid_.h;
    for (int iter = 0; iter < kRefineIterations && step > 0.02 * grid_.h; ++iter) {
      const Vec3 cand = p + away * step;
      if (squared_norm(away) == 0.0 || norm(cand - v) > leash) {
        step *= 0.5;
        continue;
      }
      Vec3 cand_away{};
      const double f = free_at(cand, best + step + slack, &cand_away);
      if (f > best) {
        best = f;
        p = cand;
        away = cand_away;
      } else {
        step *= 0.5;
      }
    }
  }

  // Places the largest free sphere near voxel `uid` (its free radius below `key`); false, and the
  // voxel removed, when none fits.
  bool place_at(std::size_t uid, float key) {
    const Vec3 v = grid_.centre(interior_.cell_of_id[uid]);
    Vec3 p = v;
    const double slack = 0.1 * grid_.h;
    Vec3 away{};
    double best = free_at(p, static_cast<double>(key) * 1.001 + slack, &away);
    if (options_.refine_centres) refine_centre(v, kLeash * static_cast<double>(dsurf_[uid]), slack, p, away, best);
    // final radius from the float centre actually stored
    Sphere s{static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), 0.f};
    const Vec3 pf = to_vec(s);
    const double r = free_at(pf, best + slack, nullptr) - margin_;
    if (!(r > min_radius_) || !bvh_.inside_vote(pf)) {
      remove(uid);
      return false;
    }
    s.radius = static_cast<float>(r);
    if (static_cast<double>(s.radius) > r) s.radius = std::nextafter(s.radius, 0.f);
    const auto sid = static_cast<std::int32_t>(spheres_.size());
    spheres_.push_back(s);
    sgrid_.insert(s, sid);
    lower_free_radii(pf, static_cast<double>(s.radius), key);
    return true;
  }

  // Lowers the free radius of the voxels within reach of a new sphere (centre pf, radius rs);
  // voxels whose centre it covers are removed.
  void lower_free_radii(const Vec3& pf, double rs, float key) {
    const double h = grid_.h;
    const Vec3& origin = grid_.origin;
    const double affect = rs + static_cast<double>(key) + h;
    auto lo_cell = [&](double c, double o, std::int64_t n) {
      return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor((c - affect - o) / h)), 0, n - 1);
    };
    auto hi_cell = [&](double c, double o, std::int64_t n) {
      return std::clamp<std::int64_t>(static_cast<std::int64_t>(std::ceil((c + affect - o) / h)), 0, n - 1);
    };
    const std::int64_t i0 = lo_cell(pf.x, origin.x, grid_.nx), i1 = hi_cell(pf.x, origin.x, grid_.nx);
    const std::int64_t j0 = lo_cell(pf.y, origin.y, grid_.ny), j1 = hi_cell(pf.y, origin.y, grid_.ny);
    const std::int64_t k0 = lo_cell(pf.z, origin.z, grid_.nz), k1 = hi_cell(pf.z, origin.z, grid_.nz);
    for (std::int64_t k = k0; k <= k1; ++k) {
      const double dz = origin.z + (static_cast<double>(k) + 0.5) * h - pf.z;
      for (std::int64_t j = j0; j <= j1; ++j) {
        // only the row's chord through the ball of radius `affect` (half the cube's voxels)
        const double dy = origin.y + (static_cast<double>(j) + 0.5) * h - pf.y;
        const double chord2 = affect * affect - dy * dy - dz * dz;
        if (chord2 < 0.0) continue;
        const double chord = std::sqrt(chord2);
        const std::int64_t ia = std::max(i0, static_cast<std::int64_t>(std::floor((pf.x - chord - origin.x) / h - 0.5)));
        const std::int64_t ib = std::min(i1, static_cast<std::int64_t>(std::ceil((pf.x + chord - origin.x) / h - 0.5)));
        for (std::int64_t i = ia; i <= ib; ++i) lower_free_radius(grid_.cell(i, j, k), grid_.centre(i, j, k), pf, rs);
      }
    }
  }

  void lower_free_radius(std::int64_t cell, const Vec3& centre, const Vec3& pf, double rs) {
    const std::int32_t w = interior_.id_of_cell[static_cast<std::size_t>(cell)];
    if (w < 0 || removed_[static_cast<std::size_t>(w)] != 0) return;
    const double dd = norm(centre - pf) - rs;
    if (dd < static_cast<double>(fsph_[static_cast<std::size_t>(w)])) {
      fsph_[static_cast<std::size_t>(w)] = static_cast<float>(dd);
      if (dd <= min_radius_) remove(static_cast<std::size_t>(w));
    }
  }

  const VoxelGrid& grid_;
  const detail::TriangleBvh& bvh_;
  const Interior& interior_;
  const PackingOptions& options_;
  Progress& progress_;
  std::vector<float> dsurf_;  // upper bounds of the surface distance, exact once exact_ is set
  std::vector<float> fsph_;   // free radius left by the placed spheres
  std::vector<char> exact_;
  std::vector<char> removed_;
  std::int64_t removed_count_ = 0;
  BucketQueue queue_;
  double min_radius_;
  double margin_;
  double max_radius_;
  detail::SphereGrid sgrid_;
  std::vector<Sphere> spheres_;
};

// Stage 4 (progress 0.95 to 1): the packing's figures.
SpherePacking make_packing(const TriangleMesh& mesh, double volume, const VoxelGrid& grid, std::int64_t voxel_count,
                           std::vector<Sphere> spheres, const PackingOptions& options) {
  SpherePacking out;
  out.report.sphere_count = static_cast<std::int64_t>(spheres.size());
  out.report.mesh_volume = volume;
  out.report.voxel_size = grid.h;
  out.report.voxel_count = voxel_count;
  double sv = 0.0;
  double rmin = std::numeric_limits<double>::infinity();
  double rmax = 0.0;
  for (const Sphere& s : spheres) {
    const double r = static_cast<double>(s.radius);
    sv += 4.0 / 3.0 * kPi * r * r * r;
    rmin = std::min(rmin, r);
    rmax = std::max(rmax, r);
  }
  out.report.sphere_volume = sv;
  out.report.coverage = sv / volume;
  out.report.min_radius = spheres.empty() ? 0.0 : rmin;
  out.report.max_radius = rmax;
  out.report.max_gap = measure_max_gap(mesh, spheres, options.gap_samples_per_triangle);
  out.spheres = std::move(spheres);
  return out;
}

}  // namespace

Result<SpherePacking> pack_spheres(const TriangleMesh& mesh, const PackingOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Progress progress(options.progress);
  progress.report(0.0);
  if (auto checked = check_mesh_to_pack(mesh); !checked) return checked.error();
  // open meshes are packed as if their holes were closed by flat fans
  const TriangleMesh capped = mesh.report.assumed_open ? cap_holes(mesh) : TriangleMesh{};
  const TriangleMesh& solid = mesh.report.assumed_open ? capped : mesh;
  const double volume = mesh_volume(solid);
  if (!(volume > 0.0))
    return Error{fmt::format("{}: cannot pack spheres: the mesh encloses no volume ({})", mesh.source_name, volume)};
  if (auto checked = check_packing_options(mesh.source_name, options); !checked) return checked.error();
  const Result<VoxelGrid> grid = make_voxel_grid(mesh, volume, options);
  if (!grid) return grid.error();

  const detail::TriangleBvh bvh(solid.vertices, solid.triangles);
  const Interior interior = classify_voxels(*grid, bvh, progress);
  if (interior.count() == 0) {
    return Error{fmt::format("{}: no voxel centre lies inside the mesh at voxel size {}; use a smaller voxel size",
                             mesh.source_name, grid->h)};
  }
  std::vector<float> distances = surface_distances(solid, *grid, interior, progress);
  std::vector<Sphere> spheres = GreedyPacker(*grid, bvh, interior, std::move(distances), options, progress).run();
  progress.report(0.95);

  SpherePacking out = make_packing(mesh, volume, *grid, interior.count(), std::move(spheres), options);
  out.report.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.report(1.0);
  return out;
}

}  // namespace uh::collette
