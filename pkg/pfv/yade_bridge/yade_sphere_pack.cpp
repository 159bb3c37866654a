#include "pfv/yade_bridge/yade_sphere_pack.hpp"

#include <vector>

#ifdef PFV_HAVE_BOOST_PYTHON
#include <boost/python/extract.hpp>
#include <boost/python/handle.hpp>
#include <boost/python/object.hpp>

// Only the name matters: Boost.Python finds a registered class by the name of its type_info.
namespace yade {
class SpherePack {};
}  // namespace yade
#endif

namespace py = pybind11;

namespace pfv {
namespace {

// The pinned YADE (yade_version.hpp), yade-double: SpherePack::Sph and the start of SpherePack.
struct PackedSphere {
  double centre[3];
  double radius;
  int clump_id;
};
static_assert(sizeof(PackedSphere) == 40, "layout of yade::SpherePack::Sph with Real = double");
struct PackLayout {
  std::vector<PackedSphere> pack;
};

const std::vector<PackedSphere>* spheres_of(py::handle pack) {
#ifdef PFV_HAVE_BOOST_PYTHON
  boost::python::object o(boost::python::handle<>(boost::python::borrowed(pack.ptr())));
  boost::python::extract<yade::SpherePack&> e(o);
  if (!e.check()) return nullptr;
  const auto* spheres = &reinterpret_cast<const PackLayout*>(&e())->pack;
  // Cheap guards against a wrong layout reading pointers that are no vector: the caller's
  // comparison with YADE's values is the real check.
  const auto* begin = reinterpret_cast<const char* const*>(spheres);
  if (begin[0] > begin[1] || begin[1] > begin[2] || (begin[1] - begin[0]) % sizeof(PackedSphere) != 0 ||
      (begin[0] == nullptr) != (begin[1] == nullptr))
    return nullptr;
  return spheres;
#else
  (void)pack;
  return nullptr;
#endif
}

}  // namespace

long long sphere_pack_size(py::handle pack) {
  const auto* spheres = spheres_of(pack);
  return spheres ? static_cast<long long>(spheres->size()) : -1;
}

bool gather_sphere_pack(py::handle pack, const py::array_t<long long>& index, py::array_t<double>& centres,
                        py::object radii, long long expected_size) {
  const auto* spheres = spheres_of(pack);
  if (!spheres) throw py::value_error("gather_sphere_pack: not a SpherePack this build of pfv can read");
  const auto n = static_cast<long long>(spheres->size());
  if (expected_size >= 0 && n != expected_size) return false;
  const auto k = index.unchecked<1>();
  if (centres.ndim() != 2 || centres.shape(0) != k.shape(0) || centres.shape(1) != 3)
    throw py::value_error("gather_sphere_pack: centres must have shape (len(index), 3)");
  auto c = centres.mutable_unchecked<2>();
  double* r = nullptr;
  if (!radii.is_none()) {  // written in place: no converting copy
    auto a = py::reinterpret_borrow<py::array>(radii);
    if (!py::isinstance<py::array>(radii) || !a.dtype().is(py::dtype::of<double>()) || a.ndim() != 1 ||
        a.shape(0) != k.shape(0) || !a.writeable() || !(a.flags() & py::array::c_style))
      throw py::value_error("gather_sphere_pack: radii must be a writeable float64 array of len(index)");
    r = static_cast<double*>(a.mutable_data());
  }
  const PackedSphere* s = spheres->data();
  for (py::ssize_t i = 0; i < k.shape(0); ++i) {
    const long long j = k(i);
    if (j < 0 || j >= n) throw py::index_error("gather_sphere_pack: sphere index outside the pack (bodies changed?)");
    c(i, 0) = s[j].centre[0], c(i, 1) = s[j].centre[1], c(i, 2) = s[j].centre[2];
    if (r) r[i] = s[j].radius;
  }
  return true;
}

}  // namespace pfv
