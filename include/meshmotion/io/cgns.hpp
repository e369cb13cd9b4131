#pragma once
/// \file
/// CGNS (.cgns) reading and writing through the CGNS library (Debian libcgns-dev): an optional
/// component. CMake defines MESHMOTION_HAVE_CGNS when it finds the library, which is then loaded
/// on first use (io/detail/cgns_library.hpp); without it read_cgns() and write_cgns() throw
/// InputError saying so, and have_cgns is false.
///
/// Reading (one base; unstructured and structured zones):
/// - Element sections of every type of the catalogue (linear and quadratic, MIXED sections
///   too) in CGNS's node order. Elements take a group named after their section (none when
///   the section is named after its element type, "TRI_3", "MIXED", ...); with several zones
///   the cells' group is named after their zone.
/// - Boundary conditions become facet groups named after the BC, or after its family when
///   it has one (families are what solvers select patches by). A BC lists elements
///   (PointList/PointRange at FaceCenter/EdgeCenter, or ElementList/ElementRange), or vertices:
///   then the facets whose vertices it all holds join it, the zone's boundary facets when the
///   file has no facet section. Facets no BC holds take a group named after their section.
/// - Several zones read as one mesh: a node of a later zone at exactly the coordinates of a
///   node of an earlier zone is that node (conforming zone interfaces), and element numbers
///   continue from one zone to the next.
/// - A structured zone (the multiblock grids of ADflow and IDWarp) reads as quadrilaterals or
///   hexahedra, i fastest; its BCs (PointRange or PointList at vertices, or at faces:
///   FaceCenter, IFaceCenter, JFaceCenter, KFaceCenter) as the facet groups of the block faces
///   they cover; block interfaces join by their coordinates, as the zones of an unstructured
///   file do. A block's 1-to-1 connection with itself (a C-grid's wake cut, an O-grid's seam)
///   makes each pair of its vertices one node where they coincide; other nodes repeated within
///   one block (a zero-thickness plate's two sides) stay apart.
/// - Refused with the CGNS node path: several bases, no zone, polyhedral
///   (NGON_n/NFACE_n) or order ≥ 3 sections, a node or element number out of range, an element
///   in two BCs, coordinates other than CoordinateX/Y/Z.
///
/// write_cgns_coordinates() writes a file that was read again with new coordinates (structured
/// zones stay blocks). write_cgns(), for any mesh: one base and one unstructured zone, double coordinates, the cells, facets and
/// lower-dimensional elements ordered by their element ids (file order for a mesh that was
/// read) and numbered 1..n in that order, one section per run of consecutive elements of one
/// group and type (MIXED where types alternate), named after the group (after the CGNS type
/// for elements without one); one BC per facet group, named after it, listing its facets
/// (PointList at FaceCenter in 3D, EdgeCenter in 2D). A mesh read from a single-zone file is
/// written back with its numbering, its sections' element ranges and its BC names. When that
/// order interleaves groups (more than 64 runs beyond one per group, as in generated meshes
/// whose facets go face by face), elements are grouped by group instead, in their order
/// within each group, and numbered in that order. The file
/// appears only once complete (temporary file and rename). The CGNS library keeps global state: do not read or write CGNS files from several
/// threads at once.
///
/// The pieces: io/cgns_reader.hpp, io/cgns_writer.hpp, io/detail/cgns_file.hpp (what both
/// share: types, node orders, the open file).

#include "meshmotion/io/cgns_reader.hpp"
#include "meshmotion/io/cgns_writer.hpp"
