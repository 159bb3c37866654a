// Darcy flow through periodic packings under a macroscopic gradient (periodic_pressure_system.hpp):
// conservation in every pore, the identities of the infinite packing (copies, translations, the
// cell's choice, cubic symmetry), regular arrays wherever they lie.
#include <gtest/gtest.h>

#include <cmath>

#include "periodic_packings.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/model/conductance.hpp"
#include "pfv/model/periodic_forces.hpp"
#include "pfv/model/periodic_pressure_system.hpp"
#include "triangulation/periodic_triangulation.hpp"

using namespace pfv;
using pfv::test::diagonal;
using pfv::test::PeriodicPacking;
using pfv::test::random_periodic;

namespace {

struct Darcy {
  std::vector<double> periodic_pressure;  // per cell
  std::vector<double> flux;               // per facet
  std::vector<double> source;
  FacetGeometry facets;
  PeriodicPressureSystem system;
  Mesh mesh;
  Vec3 velocity;
  std::vector<Vec3> force;  // per sphere
};

Darcy solve(const PeriodicPacking& p, const Vec3& gradient) {
  PeriodicTriangulation tri;
  const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
  static const BoxWalls no_walls{};
  const Packing pk{m.image_centre, m.image_radius, no_walls, &m.cell.h};
  const CellGeometry cells = compute_cell_geometry(m.mesh, pk);
  Darcy d;
  d.facets = compute_facet_geometry(m.mesh, cells, pk, false);
  const std::vector<double> k = throat_conductances(d.facets, ConductanceModel{});
  d.system = assemble_periodic_system(m.mesh, d.facets, k);
  d.source = gradient_source(cells, d.facets, k, gradient);
  std::vector<double> x(d.system.n_unknowns(), 0.0);
  if (d.system.n_unknowns() > 0) {  // else one pore: p~ is its reference value
    CholeskySolver solver;
    solver.setup(d.system.matrix, SolverOptions{});
    solver.solve(d.system.gather(d.source), x, SolveControl{});
  }
  d.periodic_pressure = d.system.scatter(x, std::vector<double>(m.n_cells(), 0.0));
  d.flux = periodic_fluxes(cells, d.facets, k, d.periodic_pressure, gradient);
  d.velocity = mean_velocity(cells, d.facets, d.flux, p.cell.volume());
  ForceCache cache;
  cache.build(m.mesh, d.facets, pk);
  PeriodicForces forces;
  forces.build(cache, m);
  d.force = forces.apply(cache, m, full_pressure(cells, d.periodic_pressure, gradient), gradient, m.cell.h);
  d.mesh = m.mesh;
  return d;
}

// kappa along the gradient's direction: mu |v| / |gradP|.
double permeability(const PeriodicPacking& p, const Vec3& direction) {
  const Darcy d = solve(p, -direction);
  return d.velocity.dot(direction.normalized()) / direction.norm();
}

PeriodicPacking cubic_array(int side, double radius, const Eigen::Matrix3d& extra_shear = Eigen::Matrix3d::Zero()) {
  PeriodicPacking p;
  p.cell.h = diagonal(side, side, side) + extra_shear;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 0; k < side; ++k) {
        p.centre.emplace_back(i + 0.5, j + 0.5, k + 0.5);
        p.radius.push_back(radius);
      }
  return p;
}

}  // namespace

TEST(PeriodicPermeability, EveryPoreConservesTheFluid) {
  Eigen::Matrix3d h = diagonal(1, 1.2, 0.9);
  h(1, 2) = 0.25;
  const auto p = random_periodic(150, 31, h, 0.05, 0.1);
  const Darcy d = solve(p, Vec3(0.3, -1.0, 0.2));
  EXPECT_EQ(d.system.n_unknowns(), static_cast<int>(d.periodic_pressure.size()) - 1);  // no merged pores
  std::vector<double> out(d.periodic_pressure.size(), 0.0);
  double largest = 0;
  for (int f = 0; f < d.facets.size(); ++f) {
    out[d.facets.cell[f][0]] += d.flux[f];
    out[d.facets.cell[f][1]] -= d.flux[f];
    largest = std::max(largest, std::abs(d.flux[f]));
  }
  // Every cell but the reference one, whose balance follows from the others'.
  for (std::size_t c = 0; c < out.size(); ++c) EXPECT_NEAR(out[c], 0.0, 1e-9 * largest) << "cell " << c;
  // The flow goes down the gradient.
  EXPECT_LT(d.velocity.dot(Vec3(0.3, -1.0, 0.2)), 0);
}

TEST(PeriodicPermeability, TheFluidPushesTheSolidWithTheGradientTimesTheVolume) {
  // Static spheres: the fluid's momentum balance over one period, sum F = -gradP V, holds in the
  // model exactly (closed cells, and sum_f d_f (x) S_f = V I over the throats of a tiling).
  Eigen::Matrix3d h = diagonal(1, 1.1, 0.95);
  h(0, 2) = 0.3;
  for (const auto& p :
       {random_periodic(120, 33, h, 0.05, 0.1), random_periodic(90, 34, diagonal(1, 1, 1), 0.08, 0.1)}) {
    const Vec3 gradient(0.4, -1.0, 0.7);
    const Darcy d = solve(p, gradient);
    Vec3 total = Vec3::Zero();
    double largest = 0;
    for (const Vec3& f : d.force) {
      total += f;
      largest = std::max(largest, f.norm());
    }
    const Vec3 expected = -gradient * p.cell.volume();
    EXPECT_LT((total - expected).norm(), 1e-8 * expected.norm()) << total.transpose() << " vs " << expected.transpose();
    EXPECT_GT(largest, 0.1 * expected.norm() / p.centre.size());
  }
}

TEST(PeriodicPermeability, ShiftingEverySphereChangesNoForce) {
  const auto p = random_periodic(80, 35, diagonal(1.1, 1, 0.9), 0.05, 0.1);
  const Vec3 gradient(0, 0, -2.0);
  const Darcy d = solve(p, gradient);
  PeriodicPacking moved = p;
  for (Vec3& x : moved.centre) x += Vec3(-0.21, 0.64, 0.33);
  const Darcy e = solve(moved, gradient);
  double largest = 0;
  for (const Vec3& f : d.force) largest = std::max(largest, f.norm());
  for (std::size_t s = 0; s < p.centre.size(); ++s)
    EXPECT_LT((d.force[s] - e.force[s]).norm(), 1e-8 * largest) << "sphere " << s;
}

TEST(PeriodicPermeability, CellsOfOnePoreShareTheirPressure) {
  // The simple cubic array: the tetrahedra of each cube of the lattice are one pore.
  PeriodicPacking p;
  p.cell.h = diagonal(2, 2, 2);
  for (int i = 0; i < 8; ++i) {
    p.centre.emplace_back(0.5 + (i & 1), 0.5 + ((i >> 1) & 1), 0.5 + ((i >> 2) & 1));
    p.radius.push_back(0.45);
  }
  const Darcy d = solve(p, Vec3(0, 0, -1));
  EXPECT_EQ(d.system.n_unknowns(), 8 - 1);  // one pore per lattice cube, less the reference
  const auto out = d.system.gather([&] {
    std::vector<double> o(d.periodic_pressure.size(), 0.0);
    for (int f = 0; f < d.facets.size(); ++f) {
      o[d.facets.cell[f][0]] += d.flux[f];
      o[d.facets.cell[f][1]] -= d.flux[f];
    }
    return o;
  }());
  for (double x : out) EXPECT_NEAR(x, 0.0, 1e-12);
  // Along z the pores of one z layer sit at one pressure: the flow has nowhere else to go.
  EXPECT_GT(d.velocity.z(), 0);
  EXPECT_NEAR(d.velocity.x(), 0.0, 1e-12 * d.velocity.z());
  EXPECT_NEAR(d.velocity.y(), 0.0, 1e-12 * d.velocity.z());
}

TEST(PeriodicPermeability, CopiesTranslationsAndTheCellsChoiceChangeNothing) {
  const auto p = random_periodic(60, 32, diagonal(1, 1.1, 0.9), 0.05, 0.1);
  const Vec3 e(0.2, 1.0, -0.4);
  const double kappa = permeability(p, e);
  ASSERT_GT(kappa, 0);
  const PeriodicPacking big = pfv::test::tiled(p);
  EXPECT_NEAR(permeability(big, e), kappa, 1e-8 * kappa);
  PeriodicPacking moved = p;
  for (Vec3& x : moved.centre) x += Vec3(0.43, 0.11, -0.72);
  EXPECT_NEAR(permeability(moved, e), kappa, 1e-8 * kappa);
  PeriodicPacking sheared = p;
  sheared.cell.h.col(0) += p.cell.h.col(2);
  EXPECT_NEAR(permeability(sheared, e), kappa, 1e-8 * kappa);
}

TEST(PeriodicPermeability, SimpleCubicArrayIsIsotropic) {
  // Spheres of radius 0.4995 on a lattice of spacing 1 (as in the comparison with YADE's
  // PeriodicFlowEngine), cospherical everywhere: the tetrahedra of one cube share its centre and
  // are one pore (periodic_pressure_system.hpp), so the array's symmetry is the model's. (The
  // array against Zick & Homsy, at their solid fractions: yade.flow.periodic_references.)
  const auto one = cubic_array(1, 0.4995);
  const double kx = permeability(one, Vec3::UnitX());
  EXPECT_NEAR(permeability(one, Vec3::UnitY()), kx, 1e-9 * kx);
  EXPECT_NEAR(permeability(one, Vec3::UnitZ()), kx, 1e-9 * kx);
  EXPECT_NEAR(permeability(cubic_array(3, 0.4995), Vec3::UnitY()), kx, 1e-9 * kx);
  Eigen::Matrix3d shear = Eigen::Matrix3d::Zero();
  shear(0, 1) = 1.0;  // sheared by one spacing: the same array
  EXPECT_NEAR(permeability(cubic_array(2, 0.4995, shear), Vec3::UnitY()), kx, 1e-9 * kx);
}

TEST(PeriodicPermeability, AFaceCentredArrayIsTheSameWhereverItLies) {
  // The face-centred array's octahedral pores are six cospherical spheres. Placed anywhere (not
  // at multiples of a power of two), its images translated in floating point would differ by
  // round-off and split those pores differently in different periods: the triangulation rounds
  // its input to a grid on which translations are exact (periodic_triangulation.cpp).
  const double r = 0.999 * std::sqrt(2.0) / 4;
  const auto fcc = [&](const Vec3& shift) {
    PeriodicPacking p;
    p.cell.h = diagonal(2, 2, 2);
    const Vec3 basis[] = {{0.25, 0.25, 0.25}, {0.75, 0.75, 0.25}, {0.75, 0.25, 0.75}, {0.25, 0.75, 0.75}};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k)
          for (const Vec3& b : basis) {
            p.centre.push_back(Vec3(i, j, k) + b + shift);
            p.radius.push_back(r);
          }
    return p;
  };
  const double k = permeability(fcc(Vec3::Zero()), Vec3::UnitY());
  EXPECT_NEAR(permeability(fcc(Vec3::Zero()), Vec3::UnitX()), k, 1e-9 * k);
  for (const Vec3& shift : {Vec3(0.1, 0.1, 0.1), Vec3(1e-3, 0.37, -0.21), Vec3(1.0 / 3, 0, 0)})
    EXPECT_NEAR(permeability(fcc(shift), Vec3::UnitY()), k, 1e-9 * k) << shift.transpose();
}
