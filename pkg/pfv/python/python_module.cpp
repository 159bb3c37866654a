// pybind11 bindings of the C++ engine (module pfv._core). Arrays cross as numpy buffers;
// YADE's attribute names live in the Python layer (pfv/flow_engine.py), not here.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <mutex>
#include <string>
#include <tuple>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/flow_queries.hpp"
#include "pfv/engine/viscous_stability.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/model/force_parts.hpp"
#include "pfv/python/shared_engine.hpp"
#include "pfv/snapshot/snapshot.hpp"

namespace py = pybind11;
using namespace pfv;
using namespace pfv::python;

namespace {
// Applies an edit to a copy of the settings, validated by the core before it is kept.
template <class Edit>
void update(FlowEngine& e, Edit edit) {
  EngineSettings s = e.settings;
  edit(s);
  validate(s);
  e.settings = s;
}

// The settings object that holds fields of type Owner: the engine's settings or their conductance model.
template <class Settings>
auto& owner(Settings& s, EngineSettings*) {
  return s;
}
template <class Settings>
auto& owner(Settings& s, ConductanceModel*) {
  return s.conductance;
}

// Getter and setter of one setting.
template <class T, class Owner>
auto get_setting(T Owner::*field) {
  return exclusive([field](const SharedEngine& e) { return owner(e.settings, static_cast<Owner*>(nullptr)).*field; });
}
template <class T, class Owner>
auto set_setting(T Owner::*field) {
  return exclusive([field](SharedEngine& e, T v) {
    update(e, [&](EngineSettings& s) { owner(s, static_cast<Owner*>(nullptr)).*field = v; });
  });
}

// The settings that take one of a few strings: the values, each named by name_of().
const SolverKind kSolvers[] = {SolverKind::kGaussSeidel, SolverKind::kConjugateGradient, SolverKind::kCholesky,
                               SolverKind::kMultigrid, SolverKind::kAuto};
const MultigridSmoother kSmoothers[] = {MultigridSmoother::kGaussSeidel, MultigridSmoother::kJacobi,
                                        MultigridSmoother::kSplitGaussSeidel};
const Ordering kOrderings[] = {Ordering::kAuto,    Ordering::kAmd,      Ordering::kMetis, Ordering::kNestedDissection,
                               Ordering::kCholmod, Ordering::kGeometric};
std::string name_of(SolverKind k) { return std::string(to_string(k)); }
std::string name_of(MultigridSmoother k) { return std::string(to_string(k)); }
std::string name_of(Ordering k) {
  const char* names[] = {"auto", "amd", "metis", "nesdis", "cholmod", "geometric"};
  return names[static_cast<int>(k)];
}

// The value among `kinds` that the string `v` names: TypeError if `v` is no string, ValueError if it
// names none of them, both naming the setting and the strings it takes.
template <class Kind, std::size_t N>
Kind choose(const char* setting, const py::object& v, const Kind (&kinds)[N]) {
  const bool text = py::isinstance<py::str>(v);
  std::string names;
  for (Kind k : kinds) {
    if (text && v.cast<std::string>() == name_of(k)) return k;
    names += (names.empty() ? "" : ", ") + name_of(k);
  }
  const std::string message =
      std::string(setting) + " must be one of " + names + "; got " + py::repr(v).cast<std::string>();
  if (text) throw py::value_error(message);
  throw py::type_error(message);
}

// Appends a point condition (YADE's imposePressure, imposeFlux) and returns its index. Refused
// if not finite, or, on a mesh, if it lies in no pore cell (a later remesh checks again).
int add_point_condition(FlowEngine& e, std::vector<PointCondition>& list, const PointCondition& c) {
  list.push_back(c);
  try {
    validate(e.bc);
  } catch (...) {
    list.pop_back();
    throw;
  }
  if (e.has_mesh() && locate(e, c.position) < 0) {
    list.pop_back();
    throw py::value_error("the point " + describe(c.position) +
                          " lies in no pore cell (outside the walls or the packing)");
  }
  return static_cast<int>(list.size()) - 1;
}

// A function of the engine and the sphere masses (the stability bounds), run without the GIL.
template <double (*function)(const FlowEngine&, const std::vector<double>&)>
auto of_masses() {
  return exclusive([](const SharedEngine& e, const Array& mass) {
    auto m = to_vector(mass, "masses");
    py::gil_scoped_release release;
    return function(e, m);
  });
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "PFV pore-scale flow engine (C++ core)";
  m.def("set_num_threads", [](int n) {
#ifdef _OPENMP
    omp_set_num_threads(std::max(1, n));
#endif
  });
  m.def("get_max_threads", []() {
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
  });

  // The code that reads YADE's objects in place (pfv/yade_bridge/).
  bind_yade_bridge(m);
  bind_periodic(m);

  // One axis of the sphere centres straight from YADE's coordinate list for that axis
  // (yade._utils.coordsAndDisplacements(axis)[0], all bodies): no numpy round trip. One axis at
  // a time, so that only one list is alive at once.
  m.def("gather_axis", [](const py::list& coords, const py::array_t<long long>& rows, Array& out, int axis) {
    const auto r = rows.unchecked<1>();
    if (axis < 0 || axis > 2 || out.ndim() != 2 || out.shape(1) != 3 || out.shape(0) != r.shape(0))
      throw py::value_error("gather_axis: out must have shape (len(rows), 3) and axis be 0, 1 or 2");
    auto o = out.mutable_unchecked<2>();
    const py::ssize_t n = PyList_GET_SIZE(coords.ptr());
    for (py::ssize_t i = 0; i < r.shape(0); ++i) {
      const py::ssize_t row = r(i);
      if (row < 0 || row >= n) throw py::index_error("body row out of range (bodies changed?)");
      o(i, axis) = PyFloat_AsDouble(PyList_GET_ITEM(coords.ptr(), row));
    }
    if (PyErr_Occurred()) throw py::error_already_set();
  });

  EngineClass engine(m, "Engine");
  engine
      .def(py::init<>())
      // Settings: forwarded as they are; the core validates them (validate()) and decides at
      // the next step what a change makes stale.
      .def_property("viscosity", get_setting(&ConductanceModel::viscosity), set_setting(&ConductanceModel::viscosity))
      .def_property("permeability_factor", get_setting(&ConductanceModel::permeability_factor),
                    set_setting(&ConductanceModel::permeability_factor))
      .def_property("clamp_k_values", get_setting(&ConductanceModel::clamp), set_setting(&ConductanceModel::clamp))
      .def_property("conductance_entrance", get_setting(&ConductanceModel::entrance),
                    set_setting(&ConductanceModel::entrance))
      .def_property("min_k_div_k_mean", get_setting(&ConductanceModel::min_ratio),
                    set_setting(&ConductanceModel::min_ratio))
      .def_property("max_k_div_k_mean", get_setting(&ConductanceModel::max_ratio),
                    set_setting(&ConductanceModel::max_ratio))
      .def_property("slip_boundary", get_setting(&EngineSettings::slip_boundary),
                    set_setting(&EngineSettings::slip_boundary))
      .def_property(
          "yade_wall_throat_factor", get_setting(&EngineSettings::yade_wall_throat_factor),
          set_setting(&EngineSettings::yade_wall_throat_factor),
          "With slip_boundary: YADE's factor on R_h of wall throats (2^-1/4 with one wall vertex, 2^-1/2 "
          "with two), as YADE's engine does; on by default, False for the thesis' formula alone; remeshes at the "
          "next step.")
      .def_property("solver",
                    exclusive([](const SharedEngine& e) { return std::string(to_string(e.settings.solver)); }),
                    exclusive([](SharedEngine& e, const py::object& v) {
                      const SolverKind k = choose("solver", v, kSolvers);
                      update(e, [&](EngineSettings& s) { s.solver = k; });
                    }),
                    "auto (default): the Cholesky factor unless it would exceed max_factor_bytes or CHOLMOD's 32-bit "
                    "index range, then multigrid.")
      .def_property("max_factor_bytes", get_setting(&EngineSettings::max_factor_bytes),
                    set_setting(&EngineSettings::max_factor_bytes),
                    "The largest Cholesky factor solver='auto' accepts (0: half the available memory); with "
                    "solver='cholesky' a larger factor raises RuntimeError (0: all the available memory).")
      .def_property(
          "multigrid_smoother",
          exclusive([](const SharedEngine& e) { return std::string(to_string(e.settings.multigrid_smoother)); }),
          exclusive([](SharedEngine& e, const py::object& v) {
            const MultigridSmoother k = choose("multigrid_smoother", v, kSmoothers);
            update(e, [&](EngineSettings& s) { s.multigrid_smoother = k; });
          }),
          "The multigrid V-cycle's smoother: gauss_seidel (default; symmetric l1-scaled sweeps on the way down and "
          "up), jacobi (l1-scaled; cheaper for a fixed skeleton) or split_gauss_seidel (one forward sweep down, one "
          "backward sweep up); rebuilds the hierarchy at the next step.")
      .def_property_readonly("solver_choice", exclusive([](const SharedEngine& e) { return solver_choice(e); }),
                             "The current system's solver and why; empty before the first step.")
      .def_property("tolerance", get_setting(&EngineSettings::tolerance), set_setting(&EngineSettings::tolerance))
      .def_property("relax", get_setting(&EngineSettings::relax), set_setting(&EngineSettings::relax))
      .def_property("max_iterations", get_setting(&EngineSettings::max_iterations),
                    set_setting(&EngineSettings::max_iterations))
      .def_property("force_metis", get_setting(&EngineSettings::force_metis), set_setting(&EngineSettings::force_metis))
      .def_property("ordering", exclusive([](const SharedEngine& e) { return name_of(e.settings.ordering); }),
                    exclusive([](SharedEngine& e, const py::object& v) {
                      const Ordering k = choose("ordering", v, kOrderings);
                      update(e, [&](EngineSettings& s) { s.ordering = k; });
                    }))
      .def_property("mixed_precision", get_setting(&EngineSettings::mixed_precision),
                    set_setting(&EngineSettings::mixed_precision))
      .def_property("mixed_precision_min_entries", get_setting(&EngineSettings::mixed_precision_min_entries),
                    set_setting(&EngineSettings::mixed_precision_min_entries))
      .def_property("refinement_tolerance", get_setting(&EngineSettings::refinement_tolerance),
                    set_setting(&EngineSettings::refinement_tolerance))
      .def_property("cholmod_openmp_teams", get_setting(&EngineSettings::cholmod_openmp_teams),
                    set_setting(&EngineSettings::cholmod_openmp_teams))
      .def_property("reuse_ordering", get_setting(&EngineSettings::reuse_ordering),
                    set_setting(&EngineSettings::reuse_ordering))
      .def("ordering_reused",
           exclusive([](const SharedEngine& e) { return e.cholesky() && e.cholmod().ordering_given(); }))
      .def("factor_fill", exclusive([](const SharedEngine& e) { return e.cholesky() ? e.cholmod().fill() : 0.0; }))
      .def("n_unknowns", exclusive([](const SharedEngine& e) { return e.has_mesh() ? e.system().n_unknowns() : 0; }),
           "Unknown pressures of the current system (cells not imposed); 0 before the first step.")
      .def_property_readonly_static(
          "geometric_from", [](const py::object&) { return kGeometricFrom; },
          "Unknowns from which ordering='auto' orders by the geometric nested dissection (below: CHOLMOD's rule, "
          "AMD then METIS).")
      .def("reduced_precision_factor",
           exclusive([](const SharedEngine& e) { return e.cholesky() && e.cholmod().reduced_precision(); }))
      .def("refinement_contraction", exclusive([](const SharedEngine& e) { return refinement_contraction(e); }))
      .def("factor_nonzeros",
           exclusive([](const SharedEngine& e) { return e.cholesky() ? e.cholmod().factor_nonzeros() : 0.0; }))
      .def("factor_flops",
           exclusive([](const SharedEngine& e) { return e.cholesky() ? e.cholmod().factor_flops() : 0.0; }))
      .def_property("fluid_bulk_modulus", get_setting(&EngineSettings::fluid_bulk_modulus),
                    set_setting(&EngineSettings::fluid_bulk_modulus))
      .def_property("minimum_porosity", get_setting(&EngineSettings::minimum_porosity),
                    set_setting(&EngineSettings::minimum_porosity),
                    "A compressible cell stores at least minimum_porosity times its volume (YADE's minimumPorosity).")
      .def_property("volume_correction", get_setting(&EngineSettings::volume_correction),
                    set_setting(&EngineSettings::volume_correction),
                    "dV/dt of the cells without wall vertices is multiplied by this (YADE's volumeCorrection).")
      .def_property("flat_threshold", get_setting(&EngineSettings::flat_threshold),
                    set_setting(&EngineSettings::flat_threshold),
                    "Cells of at most this volume are blocked at each remesh (YADE's flatThreshold; < 0: none).")
      .def_property("interpolate_on_remesh", get_setting(&EngineSettings::interpolate_on_remesh),
                    set_setting(&EngineSettings::interpolate_on_remesh),
                    "Carry pressures and blocked cells over at a remesh for a direct incompressible solve too "
                    "(YADE's doInterpolate).")
      .def_property("background_remesh", get_setting(&EngineSettings::background_remesh),
                    set_setting(&EngineSettings::background_remesh))
      .def_property("viscous_shear", get_setting(&EngineSettings::viscous_shear),
                    set_setting(&EngineSettings::viscous_shear),
                    "Viscous shear between neighbouring spheres (YADE's viscousShear); switching it on remeshes at the "
                    "next step.")
      .def_property("shear_viscosity", get_setting(&EngineSettings::shear_viscosity),
                    set_setting(&EngineSettings::shear_viscosity),
                    "The viscosity of the shear term when positive (0, the default: viscosity); a PFV extension.")
      .def("remesh_pending", exclusive([](const SharedEngine& e) { return e.remesher().pending(); }))
      .def("wait_for_remesh", exclusive([](const SharedEngine& e) {
             py::gil_scoped_release release;
             e.remesher().wait();
           }))
      .def_property("mesh_update_interval", get_setting(&EngineSettings::mesh_update_interval),
                    set_setting(&EngineSettings::mesh_update_interval))
      .def_property("def_tolerance", get_setting(&EngineSettings::def_tolerance),
                    set_setting(&EngineSettings::def_tolerance))
      .def_property("p_zero", get_setting(&EngineSettings::p_zero), set_setting(&EngineSettings::p_zero))
      .def_property("fluid_density", get_setting(&EngineSettings::fluid_density),
                    set_setting(&EngineSettings::fluid_density),
                    "Buoyancy: > 0 adds -fluid_density V g to every sphere's fluid force (0: off).")
      .def_property(
          "gravity", exclusive([](const SharedEngine& e) {
            return std::array<double, 3>{e.settings.gravity.x(), e.settings.gravity.y(), e.settings.gravity.z()};
          }),
          exclusive([](SharedEngine& e, const std::array<double, 3>& g) {
            update(e, [&](EngineSettings& s) { s.gravity = Vec3(g[0], g[1], g[2]); });
          }),
          "The gravity of the buoyancy term (pfv.FlowEngine copies the NewtonIntegrator's).")
      // Boundary conditions.
      .def_property("bnd_is_pressure", exclusive([](const SharedEngine& e) { return e.bc.is_pressure; }),
                    exclusive([](SharedEngine& e, const std::array<bool, 6>& v) { e.bc.is_pressure = v; }))
      .def_property("bnd_value", exclusive([](const SharedEngine& e) { return e.bc.value; }),
                    exclusive([](SharedEngine& e, const std::array<double, 6>& v) {
                      BoundaryConditions bc = e.bc;
                      bc.value = v;
                      validate(bc);
                      e.bc = bc;
                    }))
      .def_property(
          "pressure_profile", exclusive([](const SharedEngine& e) {
            const PressureProfile& p = e.bc.profile;
            return py::make_tuple(p.wall, p.axis, p.position, p.pressure);
          }),
          exclusive([](SharedEngine& e, const std::tuple<int, int, std::vector<double>, std::vector<double>>& v) {
            BoundaryConditions bc = e.bc;
            bc.profile = {std::get<0>(v), std::get<1>(v), std::get<2>(v), std::get<3>(v)};
            validate(bc);
            e.bc = bc;
          }),
          "(wall, axis, positions, pressures): the pressure along an axis of a pressure wall "
          "(boundary_conditions.hpp).")
      .def(
          "set_pressure_field",
          [](SharedEngine& e, int wall, py::object fn) {
            if (wall < -1 || wall >= kWallCount) throw py::value_error("wall must be in 0..5 (or -1: none)");
            PressureField field;
            if (wall >= 0 && !fn.is_none()) {
              if (!PyCallable_Check(fn.ptr())) throw py::type_error("the pressure field must be callable");
              field.wall = wall;
              // Runs inside step(), which released the GIL: take it back for the call only.
              field.evaluate = [fn = std::move(fn)](const std::vector<Vec3>& at, std::vector<double>& p) {
                py::gil_scoped_acquire gil;
                const Array values = fn(points_to_array(at)).cast<Array>();
                if (values.ndim() != 1 || values.shape(0) != static_cast<py::ssize_t>(at.size()))
                  throw py::value_error("the pressure field must return one pressure per position");
                p.assign(values.data(), values.data() + values.shape(0));
              };
            }
            // The old field (maybe a Python callable) is dropped here, with the GIL held.
            const EngineLock lock(e);
            std::swap(e.pressure_field, field);
          },
          py::arg("wall"), py::arg("field"),
          "field(positions (n, 3)) -> n pressures of the Dirichlet cells of `wall`, called once per step (the\n"
          "right-hand side only: no new system); None or wall -1: none. It must not call the engine.")
      .def(
          "set_mesh_hook",
          [](SharedEngine& e, py::object fn) {
            std::function<void()> hook;
            if (!fn.is_none()) {
              if (!PyCallable_Check(fn.ptr())) throw py::type_error("the mesh hook must be callable or None");
              // Runs inside step(), which holds the engine's lock and released the GIL: the hook's
              // calls into the engine pass the lock (EngineLock), the GIL is taken back for the call.
              hook = [&e, fn = std::move(fn)]() {
                py::gil_scoped_acquire gil;
                e.hook_running.store(true);
                try {
                  fn();
                } catch (...) {
                  e.hook_running.store(false);
                  throw;
                }
                e.hook_running.store(false);
              };
            }
            // The old hook (maybe a Python callable) is dropped here, with the GIL held.
            const EngineLock lock(e);
            std::swap(e.mesh_hook, hook);
          },
          py::arg("hook"),
          "hook() called for every new mesh before its linear system is built (YADE's blockHook), in the\n"
          "step: it may read the engine and set conditions on cells; None: none.")
      .def("retract_step", exclusive(&FlowEngine::retract_step),
           "Undo the last step (or remesh) as if it had failed; False if there is none to undo.")
      .def("accept_step", exclusive(&FlowEngine::accept_step),
           "The last step stands: free what retract_step would need.")
      .def_property_readonly("mesh_id", exclusive(&FlowEngine::mesh_id),
                             "Grows with every mesh adopted, never repeats (a retracted remesh keeps its number).")
      .def_property_readonly("pressure_field_wall",
                             exclusive([](const SharedEngine& e) { return e.pressure_field.wall; }))
      .def_property_readonly("field_evaluations", exclusive(&FlowEngine::field_evaluations),
                             "Steps that evaluated the pressure field so far.")
      .def("impose_pressure", exclusive([](SharedEngine& e, const std::array<double, 3>& x, double p) {
             return add_point_condition(e, e.bc.imposed_pressure, {Vec3(x[0], x[1], x[2]), p});
           }))
      .def("set_imposed_pressure", exclusive([](SharedEngine& e, int i, double p) {
             if (i < 0 || i >= static_cast<int>(e.bc.imposed_pressure.size()))
               throw py::index_error("no imposed pressure with index " + std::to_string(i));
             if (!std::isfinite(p)) throw py::value_error("imposed pressure " + std::to_string(i) + " must be finite");
             e.bc.imposed_pressure[i].value = p;
           }))
      .def("clear_imposed_pressure", exclusive([](SharedEngine& e) { e.bc.imposed_pressure.clear(); }))
      .def("impose_flux", exclusive([](SharedEngine& e, const std::array<double, 3>& x, double q) {
             return add_point_condition(e, e.bc.imposed_flux, {Vec3(x[0], x[1], x[2]), q});
           }))
      .def("clear_imposed_flux", exclusive([](SharedEngine& e) { e.bc.imposed_flux.clear(); }))
      .def("request_remesh", exclusive(&FlowEngine::request_remesh))
      .def("remesh",
           exclusive([](SharedEngine& e, const Array& centres, const Array& radii, const std::array<double, 6>& walls) {
             auto c = to_points(centres, "positions");
             auto r = to_vector(radii, "radii");
             const BoxWalls w = to_walls(walls);
             py::gil_scoped_release release;
             e.remesh(c, r, w);
           }),
           py::arg("positions"), py::arg("radii"), py::arg("walls"),
           "Remesh now without a linear system: the next step builds it (for conditions set on the new cells).")
      .def("request_system_rebuild", exclusive(&FlowEngine::request_system_rebuild))
      .def("reset_history", exclusive(&FlowEngine::reset_history))
      .def("release", exclusive(&FlowEngine::release),
           "Free the mesh, the system and the results (settings kept); the next step remeshes.")
      .def("remesh_due", exclusive(&FlowEngine::remesh_due))
      .def("has_mesh", exclusive(&FlowEngine::has_mesh))
      // The step.
      .def("step",
           exclusive([](SharedEngine& e, const Array& centres, const Array& radii, const std::array<double, 6>& walls,
                        double dt) {
             auto c = to_points(centres, "positions");
             auto r = to_vector(radii, "radii");
             const BoxWalls w = to_walls(walls);
             py::gil_scoped_release release;
             e.step(c, r, w, dt);
           }),
           py::arg("positions"), py::arg("radii"), py::arg("walls"), py::arg("dt"))
      .def("viscous_stability_limit", exclusive([](const SharedEngine& e, const Array& mass, int iterations) {
             auto m = to_vector(mass, "masses");
             py::gil_scoped_release release;
             return viscous_stability_limit(e, m, iterations);
           }),
           py::arg("masses"), py::arg("iterations") = 40)
      .def("viscous_stability_bound", of_masses<&viscous_stability_bound>(), py::arg("masses"),
           "A certified lower bound on viscous_stability_limit for about one solve, up to four orders of\n"
           "magnitude below it; 0 when there is none (viscous shear on).")
      .def("viscous_stability_local_bound", of_masses<&viscous_stability_local_bound>(), py::arg("masses"),
           "A certified lower bound on viscous_stability_limit from small problems around each sphere, within an\n"
           "order of magnitude of it; 0 when there is none (viscous shear on).")
      .def("viscous_stability_mode",
           exclusive([](const SharedEngine& e, const Array& mass, int iterations, py::object start) {
             auto m = to_vector(mass, "masses");
             std::vector<Vec3> mode;
             if (!start.is_none()) mode = to_points(start.cast<Array>(), "start");
             double limit;
             int applications = 0;
             {
               py::gil_scoped_release release;
               limit = viscous_stability_limit(e, m, iterations, &mode, &applications);
             }
             return py::make_tuple(limit, points_to_array(mode), applications);
           }),
           py::arg("masses"), py::arg("iterations") = 40, py::arg("start") = py::none(),
           "(limit, mode, applications): as viscous_stability_limit, by power iteration from `start` (one\n"
           "velocity per sphere, e.g. the mode returned on the previous mesh) when given, else by Arnoldi; mode is\n"
           "the estimated eigenvector, applications the operator applications made (each a solve).")
      .def("forces", exclusive([](const SharedEngine& e) { return points_to_array(e.forces()); }),
           "Fluid force on every sphere (input order), then on the six walls.")
      .def("force_parts",
           exclusive([](const SharedEngine& e, const Array& centres, const Array& radii,
                        const std::array<double, 6>& walls) {
             const auto c = to_points(centres, "positions");
             const auto r = to_vector(radii, "radii");
             const BoxWalls w = to_walls(walls);
             const ForceParts parts = split_fluid_forces(meshed(e).mesh(), e.facets(), Packing{c, r, w}, e.pressure());
             return py::make_tuple(points_to_array(parts.pressure), points_to_array(parts.viscous));
           }),
           py::arg("positions"), py::arg("radii"), py::arg("walls"),
           "(pressure, viscous): forces() without the shear term, split into its pressure and viscous parts\n"
           "(spheres, then the six walls), for the packing of the last step (pass the same arrays).")
      .def("shear_forces", exclusive([](const SharedEngine& e) { return points_to_array(e.shear_forces()); }),
           "The viscous shear part of forces() (empty while viscous_shear is off).")
      .def("shear_pairs", exclusive([](const SharedEngine& e) {
             const ViscousShear* s = meshed(e).viscous_shear();
             if (!s) throw py::value_error("viscous_shear is off: the mesh has no shear pairs");
             py::dict d;
             d["a"] = vector_to_array(s->a);
             d["b"] = vector_to_array(s->b);
             d["direction"] = points_to_array(s->direction);
             d["area"] = vector_to_array(s->area);
             d["hydraulic_radius"] = vector_to_array(s->hydraulic_radius);
             d["open_rings"] = s->open_rings;
             return d;
           }),
           "Pairs of the shear term: vertices a, b (b >= n spheres: wall), unit a->b, S_vor, R_h.")
      .def("pressure", exclusive([](const SharedEngine& e) { return vector_to_array(e.pressure()); }))
      // Queries.
      .def("n_cells", exclusive([](const SharedEngine& e) { return e.has_mesh() ? e.mesh().n_cells() : 0; }))
      .def("boundary_flux", exclusive([](const SharedEngine& e, int w) {
             check_wall(w);
             return boundary_flux(e, w);
           }))
      .def("imposed_flux_total", exclusive([](const SharedEngine& e) { return imposed_flux_total(e); }))
      .def("volume_rate_total", exclusive([](const SharedEngine& e) { return volume_rate_total(e); }))
      .def("average_pressure", exclusive([](const SharedEngine& e) { return average_pressure(e); }))
      .def("average_slice_pressure", exclusive([](const SharedEngine& e, int axis, double position) {
             return average_slice_pressure(e, axis, position);
           }))
      .def("locate", exclusive([](const SharedEngine& e, const std::array<double, 3>& x) {
             return locate(e, Vec3(x[0], x[1], x[2]));
           }))
      .def("cell_pressure", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return e.pressure()[id];
           }))
      .def("cell_center", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             const Vec3& c = meshed(e).cells().power_centre[id];
             return std::array<double, 3>{c.x(), c.y(), c.z()};
           }))
      .def("cell_volume", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return meshed(e).cells().volume[id];
           }))
      .def("cell_fluid_volume", exclusive([](const SharedEngine& e, int id) {
             check_cell(e, id);
             return meshed(e).cells().fluid_volume[id];
           }))
      .def("metis_used", exclusive([](const SharedEngine& e) { return metis_used(e); }))
      .def("hidden_spheres",
           exclusive([](const SharedEngine& e) { return e.has_mesh() ? e.mesh().hidden_spheres : std::vector<int>{}; }))
      .def_property_readonly("remesh_count", exclusive(&FlowEngine::remesh_count))
      .def_property_readonly("inversion_remeshes", exclusive(&FlowEngine::inversion_remeshes),
                             "Remeshes forced by 2 % of the meshed volume turned inside out (motion too large\n"
                             "for the schedule).")
      .def_property_readonly("inverted_cells", exclusive(&FlowEngine::inverted_cells),
                             "Cells inside out at the last step's positions; up to 2 % of the volume inside out\n"
                             "the step runs on with signed volumes (mass conserved) until the scheduled remesh.")
      .def_property_readonly("inverted_volume_fraction", exclusive(&FlowEngine::inverted_volume_fraction),
                             "The part of the meshed volume inverted_cells hold.")
      .def_property_readonly("mesh_viscosity", exclusive([](const SharedEngine& e) { return mesh_viscosity(e); }),
                             "The viscosity of the current mesh's conductances.")
      .def_property_readonly("system_builds", exclusive(&FlowEngine::system_builds))
      .def_property_readonly("sweeps", exclusive([](const SharedEngine& e) { return e.last_solve().sweeps; }),
                             "Gauss-Seidel sweeps of the last solve.")
      .def_property_readonly("cg_iterations",
                             exclusive([](const SharedEngine& e) { return e.last_solve().cg_iterations; }),
                             "Conjugate-gradient iterations of the last solve.")
      .def_property_readonly("converged", exclusive([](const SharedEngine& e) { return e.last_solve().converged; }),
                             "False if the last solve was iterative and stopped at max_iterations above its tolerance.")
      .def_property_readonly("refinement_passes",
                             exclusive([](const SharedEngine& e) { return e.last_solve().refinement_passes; }),
                             "Refinement passes of the last solve with a 32-bit factor.")
      .def_property_readonly("accumulated_strain",
                             exclusive([](const SharedEngine& e) { return e.remesher().strain(); }))
      .def("walls", exclusive([](const SharedEngine& e) { return e.walls().coord; }))
      .def("remesh_times", exclusive([](const SharedEngine& e) { return times_dict(e.remesh_times()); }))
      .def("step_times", exclusive([](const SharedEngine& e) { return times_dict(e.step_times()); }));
  bind_geometry(engine);
  bind_persistence(engine);
  bind_output(engine);
  bind_cells(engine);
}
