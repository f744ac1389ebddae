#include "uh/soft/soft_body.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace uh::soft {
namespace {

Eigen::Matrix3d edge_matrix(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            const Eigen::Vector3d& d) {
  Eigen::Matrix3d m;
  m << b - a, c - a, d - a;
  return m;
}

const Eigen::Vector3d& node_of(const std::vector<Eigen::Vector3d>& positions, std::int32_t node) {
  return positions[static_cast<std::size_t>(node)];
}

Eigen::Matrix3d tet_edges(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& positions, std::size_t tet) {
  const auto& t = mesh.tets[tet];
  return edge_matrix(node_of(positions, t[0]), node_of(positions, t[1]), node_of(positions, t[2]),
                     node_of(positions, t[3]));
}

// Buckets of tetrahedra on a uniform grid over the mesh, by their bounding boxes: a point is
// looked up among the few tetrahedra of its bucket.
class TetLocator {
 public:
  TetLocator(const TetMesh& mesh, const std::vector<Eigen::Matrix3d>& rest_inverse)
      : mesh_(mesh), rest_inverse_(rest_inverse) {
    min_ = max_ = mesh.nodes.front();
    for (const auto& p : mesh.nodes) {
      min_ = min_.cwiseMin(p);
      max_ = max_.cwiseMax(p);
    }
    const Eigen::Vector3d extent = (max_ - min_).cwiseMax(1e-12);
    const double cell = std::cbrt(extent.prod() / static_cast<double>(mesh.tets.size()));
    for (int axis = 0; axis < 3; ++axis) cells_[axis] = std::clamp(static_cast<int>(extent[axis] / cell), 1, 256);
    size_ = extent.cwiseQuotient(cells_.cast<double>());
    buckets_.resize(static_cast<std::size_t>(cells_.prod()));
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
      Eigen::Vector3d lo = mesh.nodes[static_cast<std::size_t>(mesh.tets[t][0])], hi = lo;
      for (std::int32_t n : mesh.tets[t]) {
        lo = lo.cwiseMin(mesh.nodes[static_cast<std::size_t>(n)]);
        hi = hi.cwiseMax(mesh.nodes[static_cast<std::size_t>(n)]);
      }
      const Eigen::Vector3i a = cell_of(lo), b = cell_of(hi);
      for (int z = a.z(); z <= b.z(); ++z)
        for (int y = a.y(); y <= b.y(); ++y)
          for (int x = a.x(); x <= b.x(); ++x) buckets_[bucket(x, y, z)].push_back(static_cast<std::int32_t>(t));
    }
  }

  // the tetrahedron holding p with the largest smallest weight (a point on a shared face is in
  // both), or none when no weight of any candidate is above -tolerance
  std::optional<EmbeddedSphere> locate(const Eigen::Vector3d& p) const {
    std::optional<EmbeddedSphere> best;
    double best_min = -1e-9;
    const Eigen::Vector3i c = cell_of(p);
    for (std::int32_t t : buckets_[bucket(c.x(), c.y(), c.z())]) {
      const Eigen::Vector4d w = weights_in(t, p);
      if (w.minCoeff() < best_min) continue;
      best_min = w.minCoeff();
      const Eigen::Vector4d clamped = w.cwiseMax(0.0);
      best = EmbeddedSphere{.tet = t, .weights = clamped / clamped.sum(), .rest_radius = 0.0};
    }
    return best;
  }

  // p's barycentric weights in tetrahedron t, negative outside it
  Eigen::Vector4d weights_in(std::int32_t t, const Eigen::Vector3d& p) const {
    const Eigen::Vector3d b =
        rest_inverse_[static_cast<std::size_t>(t)] * (p - mesh_.nodes[static_cast<std::size_t>(mesh_.tets[static_cast<std::size_t>(t)][0])]);
    return {1.0 - b.sum(), b.x(), b.y(), b.z()};
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d at = (p - min_).cwiseQuotient(size_);
    Eigen::Vector3i c;
    for (int axis = 0; axis < 3; ++axis)
      c[axis] = std::clamp(static_cast<int>(std::floor(at[axis])), 0, cells_[axis] - 1);
    return c;
  }
  std::size_t bucket(int x, int y, int z) const {
    return static_cast<std::size_t>(x + cells_.x() * (y + cells_.y() * z));
  }

  const TetMesh& mesh_;
  const std::vector<Eigen::Matrix3d>& rest_inverse_;
  Eigen::Vector3d min_, max_, size_;
  Eigen::Vector3i cells_;
  std::vector<std::vector<std::int32_t>> buckets_;
};

Eigen::Vector3d centre_of(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

Status embed_leaves(const TetLocator& locator, std::span<const Sphere> leaves, SoftBodyModel& body) {
  body.spheres.reserve(leaves.size());
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    auto embedded = locator.locate(centre_of(leaves[i]));
    if (!embedded)
      return Error{"soft::build_soft_body: leaf sphere " + std::to_string(i) + "'s centre lies in no tetrahedron",
                   ErrorKind::kMesh};
    embedded->rest_radius = static_cast<double>(leaves[i].radius);
    body.spheres.push_back(*embedded);
  }
  return Ok{};
}

bool in_box(const Box& box, const Eigen::Vector3d& p) {
  return (p.array() >= box.min.array()).all() && (p.array() <= box.max.array()).all();
}

// the tetrahedron whose centroid is nearest p: brute force, for the few vertices outside the
// lattice (all its tetrahedra have the same size and shape, so the nearest centroid is the
// nearest element)
std::int32_t nearest_tet(const TetMesh& mesh, const Eigen::Vector3d& p) {
  std::int32_t nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (std::int32_t n : mesh.tets[t]) centroid += 0.25 * mesh.nodes[static_cast<std::size_t>(n)];
    if (const double d = (centroid - p).squaredNorm(); d < best) {
      best = d;
      nearest = static_cast<std::int32_t>(t);
    }
  }
  return nearest;
}

// each surface vertex in its tetrahedron with weights that give its rest position exactly
// (extrapolated outside the lattice), or held in the fixed box
void embed_surface(const TetLocator& locator, const std::optional<Box>& fixed, SoftBodyModel& body) {
  body.surface_embedding.reserve(body.surface.vertices.size());
  for (const Eigen::Vector3d& v : body.surface.vertices) {
    EmbeddedVertex e;
    if (!fixed || !in_box(*fixed, v)) {
      const auto inside = locator.locate(v);
      e.tet = inside ? inside->tet : nearest_tet(body.mesh, v);
      e.weights = locator.weights_in(e.tet, v);
    }
    body.surface_embedding.push_back(e);
  }
}

}  // namespace

int default_tetrahedra(const Eigen::Vector3d& extent) {
  const double edge = extent.maxCoeff() / 10.0;
  if (!(edge > 0.0)) return 384;
  const double cells = (extent / edge).cwiseMax(1.0).prod();
  return static_cast<int>(std::clamp(6.0 * cells, 384.0, 3000.0));
}

Result<SoftBodyModel> build_soft_body(const InsidePredicate& inside, std::span<const Sphere> leaves,
                                      const SoftBodyParams& params) {
  if (leaves.empty()) return Error{"soft::build_soft_body: the packing has no spheres", ErrorKind::kInvalid};
  LatticeOptions lattice;
  lattice.min = lattice.max = centre_of(leaves.front());
  for (const Sphere& s : leaves) {
    const Eigen::Vector3d r = Eigen::Vector3d::Constant(static_cast<double>(s.radius));
    lattice.min = lattice.min.cwiseMin(centre_of(s) - r);
    lattice.max = lattice.max.cwiseMax(centre_of(s) + r);
    lattice.cover.push_back(centre_of(s));
  }
  lattice.target_tetrahedra =
      params.target_tetrahedra > 0 ? params.target_tetrahedra : default_tetrahedra(lattice.max - lattice.min);
  auto mesh = build_voxel_lattice(inside, lattice);
  if (!mesh) return mesh.error();
  SoftBodyModel body;
  body.mesh = std::move(*mesh);
  body.material = params.material;
  body.rest_inverse.reserve(body.mesh.tets.size());
  for (std::size_t t = 0; t < body.mesh.tets.size(); ++t)
    body.rest_inverse.push_back(tet_edges(body.mesh, body.mesh.nodes, t).inverse());
  if (params.fixed) {
    body.fixed = nodes_in_box(body.mesh, params.fixed->min, params.fixed->max);
    if (body.fixed.empty())
      return Error{"soft::build_soft_body: the fixed box holds no node of the lattice (the box is in metres, object frame)",
                   ErrorKind::kInvalid};
  }
  const TetLocator locator(body.mesh, body.rest_inverse);
  if (Status s = embed_leaves(locator, leaves, body); !s) return s.error();
  body.spheres_by_tet.resize(body.spheres.size());
  std::iota(body.spheres_by_tet.begin(), body.spheres_by_tet.end(), 0);
  std::stable_sort(body.spheres_by_tet.begin(), body.spheres_by_tet.end(), [&](std::int32_t a, std::int32_t b) {
    return body.spheres[static_cast<std::size_t>(a)].tet < body.spheres[static_cast<std::size_t>(b)].tet;
  });
  body.surface = params.surface;
  embed_surface(locator, params.fixed, body);
  return body;
}

namespace {

// A tetrahedron's smallest principal stretch: the smallest singular value of its deformation
// gradient F, the square root of F^T F's smallest eigenvalue (closed form, several times quicker
// than an SVD); an inverted element's is taken as 0. At least kMinSphereStretch.
double smallest_stretch(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& positions, std::size_t tet) {
  const Eigen::Matrix3d f = tet_edges(body.mesh, positions, tet) * body.rest_inverse[tet];
  if (!(f.determinant() > 0.0)) return kMinSphereStretch;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(f.transpose() * f, Eigen::EigenvaluesOnly);
  return std::max(std::sqrt(std::max(eigen.eigenvalues().minCoeff(), 0.0)), kMinSphereStretch);
}

}  // namespace

void deform_spheres(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& positions, std::span<Sphere> out) {
  const std::size_t n = std::min(out.size(), body.spheres.size());
  const bool by_tet = body.spheres_by_tet.size() == body.spheres.size();
  std::int32_t last_tet = -1;
  double stretch = 1.0;
  for (std::size_t k = 0; k < body.spheres.size(); ++k) {
    const auto i = by_tet ? static_cast<std::size_t>(body.spheres_by_tet[k]) : k;
    if (i >= n) continue;
    const EmbeddedSphere& e = body.spheres[i];
    const auto tet = static_cast<std::size_t>(e.tet);
    if (e.tet != last_tet) {
      stretch = smallest_stretch(body, positions, tet);
      last_tet = e.tet;
    }
    const auto& t = body.mesh.tets[tet];
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int c = 0; c < 4; ++c) centre += e.weights[c] * node_of(positions, t[static_cast<std::size_t>(c)]);
    out[i] = Sphere{static_cast<float>(centre.x()), static_cast<float>(centre.y()), static_cast<float>(centre.z()),
                    static_cast<float>(e.rest_radius * stretch)};
  }
}

void deform_surface(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& positions, std::span<float> xyz) {
  const std::size_t n = std::min(xyz.size() / 3, body.surface_embedding.size());
  for (std::size_t i = 0; i < n; ++i) {
    const EmbeddedVertex& e = body.surface_embedding[i];
    Eigen::Vector3d p = body.surface.vertices[i];
    if (e.tet != EmbeddedVertex::kHeldVertex) {
      const auto& t = body.mesh.tets[static_cast<std::size_t>(e.tet)];
      p.setZero();
      for (int k = 0; k < 4; ++k) p += e.weights[k] * node_of(positions, t[static_cast<std::size_t>(k)]);
    }
    for (int axis = 0; axis < 3; ++axis) xyz[3 * i + static_cast<std::size_t>(axis)] = static_cast<float>(p[axis]);
  }
}

void spread_sphere_force(const SoftBodyModel& body, std::int32_t leaf, const Eigen::Vector3d& force,
                         std::vector<Eigen::Vector3d>& nodal_loads) {
  const EmbeddedSphere& e = body.spheres[static_cast<std::size_t>(leaf)];
  const auto& t = body.mesh.tets[static_cast<std::size_t>(e.tet)];
  for (int k = 0; k < 4; ++k) nodal_loads[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])] += e.weights[k] * force;
}

}  // namespace uh::soft
