// The CGAL regular triangulation both meshes build on (regular_triangulation.cpp for walled
// boxes, periodic_triangulation.cpp for periodic cells): exact predicates, inexact
// constructions, an int of info on every vertex (the point's index) and cell (the pore's), and
// hidden points discarded (the meshes report them from the vertices). Included by those two
// sources only: CGAL stays out of the library's interface.
#pragma once
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

namespace pfv::cgal_regular {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K, CGAL::Regular_triangulation_vertex_base_3<K>>;
using Cb = CGAL::Triangulation_cell_base_with_info_3<
    int, K,
    CGAL::Regular_triangulation_cell_base_3<K, CGAL::Triangulation_cell_base_3<K>, CGAL::Discard_hidden_points>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using RT = CGAL::Regular_triangulation_3<K, Tds>;
using WPoint = RT::Weighted_point;

}  // namespace pfv::cgal_regular
