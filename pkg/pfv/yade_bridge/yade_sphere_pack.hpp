// Reads the sphere centres out of a yade.pack.SpherePack filled by its fromSimulation(): YADE's
// own C++ loop over the bodies copies (centre, radius) of every sphere, in id order, into the
// pack's array, several times faster than building the three coordinate lists of
// yade._utils.coordsAndDisplacements (bench/solver_stages.py --sections=4; doc/yade.md).
//
// Debian's YADE ships no headers, so the pack's array is reached as the Vector3 storage in
// yade_force_bridge.hpp is: through Boost.Python's converter registry, which YADE's bindings
// populate, and then through the layout of the pinned YADE's class (yade_version.hpp; first member
// std::vector<Sph>, Sph = {Vector3r c; Real r; int clumpId}). A layout is a property of the
// YADE build, not of the run: the caller checks it against YADE's Python interface (every
// centre and radius) before trusting it, and reads the coordinate lists if it does not hold.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace pfv {

// Number of spheres in the pack, or -1 if `pack` is not a SpherePack this build can read
// (no Boost.Python, another YADE, another object).
long long sphere_pack_size(pybind11::handle pack);

// centres[i] = centre of pack sphere index[i], radii[i] (if given) its radius; returns false,
// writing nothing, if expected_size >= 0 and the pack holds another number of spheres (bodies
// were erased or added since the index was made). Throws ValueError if the pack cannot be read
// or the shapes do not match, IndexError if an index is outside the pack.
bool gather_sphere_pack(pybind11::handle pack, const pybind11::array_t<long long>& index,
                        pybind11::array_t<double>& centres, pybind11::object radii, long long expected_size);

}  // namespace pfv
