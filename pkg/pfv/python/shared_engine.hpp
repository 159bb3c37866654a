// What every file of pybind11 bindings of pfv._core shares: the engine as Python holds it (with
// the lock that serialises calls from YADE's simulation thread and the main thread), the
// wrapper that takes that lock, and the numpy conversions. The bindings are grouped by topic,
// one file each; python_module.cpp defines the module and calls the groups.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pfv/engine/flow_engine.hpp"

namespace pfv::python {

namespace py = pybind11;

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// The stage times of a remesh or step as a dict (stage -> seconds).
py::dict times_dict(const StageTimes& t);
// Point conditions as [((x, y, z), value), ...].
py::list conditions(const std::vector<PointCondition>& list);
// Four vertex indices per cell as an (n, 4) array.
py::array_t<int> cell_vertices_array(const std::vector<std::array<int, 4>>& cells);

inline std::vector<Vec3> to_points(const Array& a, const char* name) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string(name) + " must have shape (n, 3)");
  std::vector<Vec3> out(a.shape(0));
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  if (!out.empty()) std::memcpy(static_cast<void*>(out.data()), a.data(), out.size() * sizeof(Vec3));
  return out;
}

inline std::vector<double> to_vector(const Array& a, const char* name) {
  if (a.ndim() != 1) throw py::value_error(std::string(name) + " must be one-dimensional");
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

inline Array points_to_array(const std::vector<Vec3>& v) {
  Array out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(Vec3));
  return out;
}

template <class T>
py::array_t<T> vector_to_array(const std::vector<T>& v) {
  return py::array_t<T>(static_cast<py::ssize_t>(v.size()), v.data());
}

inline BoxWalls to_walls(const std::array<double, 6>& w) {
  BoxWalls b;
  b.coord = w;
  return b;
}

// The engine as Python holds it. YADE runs O.run() on a thread of its own, so a query from the
// main thread may arrive while a step rebuilds the mesh. Every call into the engine takes its
// lock; a caller that must wait does so with the GIL released (a step releases the GIL while it
// runs, and never needs it while it holds the lock), so the two threads cannot deadlock.
// A call from the thread that holds the lock (a boundary-pressure function calling the engine
// during the step that calls it) would wait for itself forever: it raises instead, except from the
// mesh hook (blockHook), which the step runs at a point where the engine is whole and which may
// read it and set conditions on cells (the engine refuses the rest, FlowEngine::mesh_hook).
struct SharedEngine : FlowEngine {
  mutable std::mutex busy;
  mutable std::atomic<std::thread::id> holder{};
  mutable std::atomic<bool> hook_running{false};
};

class EngineLock {
 public:
  explicit EngineLock(const SharedEngine& e) : engine_(e), lock_(e.busy, std::defer_lock) {
    if (e.holder.load() == std::this_thread::get_id()) {
      if (e.hook_running.load()) return;  // inside the step's own lock: nothing to take
      throw std::runtime_error(
          "pfv.Engine called from inside its own step (a boundary-pressure function must not call the engine; "
          "compute what it needs before the step)");
    }
    if (!lock_.try_lock()) {
      py::gil_scoped_release release;
      lock_.lock();
    }
    e.holder.store(std::this_thread::get_id());
  }
  ~EngineLock() {
    if (lock_.owns_lock()) engine_.holder.store(std::thread::id{});  // before the lock is released
  }
  EngineLock(const EngineLock&) = delete;
  EngineLock& operator=(const EngineLock&) = delete;

 private:
  const SharedEngine& engine_;
  std::unique_lock<std::mutex> lock_;
};

// f(engine, args...) under the engine's lock, for a lambda taking the engine first ...
template <class F, class R, class Self, class... A>
auto exclusive_call(F f, R (F::*)(Self, A...) const) {
  return [f = std::move(f)](Self e, A... a) -> R {
    const EngineLock lock(e);
    return f(e, std::forward<A>(a)...);
  };
}
template <class F>
auto exclusive(F f) {
  return exclusive_call(std::move(f), &F::operator());
}
// ... or for a member function of the engine.
template <class R, class... A>
auto exclusive(R (FlowEngine::*m)(A...) const) {
  return [m](const SharedEngine& e, A... a) -> R {
    const EngineLock lock(e);
    return (e.*m)(std::forward<A>(a)...);
  };
}
template <class R, class... A>
auto exclusive(R (FlowEngine::*m)(A...)) {
  return [m](SharedEngine& e, A... a) -> R {
    const EngineLock lock(e);
    return (e.*m)(std::forward<A>(a)...);
  };
}

inline const FlowEngine& meshed(const FlowEngine& e) {
  if (!e.has_mesh()) throw py::value_error("the engine has no pore mesh yet (run a step first)");
  return e;
}

inline void check_cell(const FlowEngine& e, int id) {
  meshed(e);
  if (id < 0 || id >= e.mesh().n_cells()) throw py::index_error("no pore cell with index " + std::to_string(id));
}

inline void check_wall(int w) {
  if (w < 0 || w >= kWallCount) throw py::index_error("wall index must be in 0..5");
}

using EngineClass = py::class_<SharedEngine>;

// The binding groups of pfv.Engine defined in files of their own (python_module.cpp calls them).
void bind_geometry(EngineClass& engine);     // geometry_bindings.cpp
void bind_output(EngineClass& engine);       // output_bindings.cpp
void bind_persistence(EngineClass& engine);  // persistence_bindings.cpp
void bind_cells(EngineClass& engine);        // cell_bindings.cpp
// The module's YADE bridge classes and functions (yade_bridge_bindings.cpp).
void bind_yade_bridge(py::module_& m);
void bind_periodic(py::module_& m);  // periodic_bindings.cpp

}  // namespace pfv::python
