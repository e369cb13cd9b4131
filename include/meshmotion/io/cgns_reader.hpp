#pragma once
/// \file
/// CGNS (.cgns) reading through the CGNS library (Debian libcgns-dev; see io/cgns.hpp for what
/// is read and what is refused). Without the library read_cgns() throws InputError saying so.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/io/any_mesh.hpp"
#include "meshmotion/io/detail/cgns_file.hpp"
#include "meshmotion/io/detail/raw_mesh.hpp"
#include "meshmotion/io/detail/read_file.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace meshmotion {

#ifdef MESHMOTION_HAVE_CGNS

namespace detail {

/// Where each element number of a zone was read to: per section its number range and the
/// block and first position of its elements (a one-type section fills one block in order), or
/// each element's block and position (a MIXED section).
class CgnsSections {
 public:
  struct Section {
    std::string path;
    std::int64_t start = 0, end = 0;
    std::size_t block = 0;
    Index first = 0;
    std::vector<std::pair<std::size_t, Index>> each;  ///< MIXED sections only
  };

  void add(Section section) { sections_.push_back(std::move(section)); }

  /// Sorts the sections by number; refuses two sections sharing a number.
  void finish(const CgnsFile& cgns) {
    std::sort(sections_.begin(), sections_.end(), [](const Section& a, const Section& b) { return a.start < b.start; });
    for (std::size_t k = 1; k < sections_.size(); ++k)
      if (sections_[k].start <= sections_[k - 1].end)
        cgns.fail(sections_[k].path, "element numbers " + std::to_string(sections_[k].start) + ".." + std::to_string(sections_[k].end) +
                                         " overlap those of " + sections_[k - 1].path);
  }

  /// The block and position of element `number`, or false.
  [[nodiscard]] bool find(std::int64_t number, std::size_t& block, Index& local) const {
    const auto it = std::upper_bound(sections_.begin(), sections_.end(), number,
                                     [](std::int64_t v, const Section& sec) { return v < sec.start; });
    if (it == sections_.begin()) return false;
    const Section& sec = *std::prev(it);
    if (number > sec.end) return false;
    const auto k = number - sec.start;
    if (sec.each.empty()) {
      block = sec.block;
      local = sec.first + k;
    } else {
      std::tie(block, local) = sec.each[static_cast<std::size_t>(k)];
    }
    return true;
  }

  /// Calls f(block, local) for every element of the zone.
  template <class F>
  void for_each(F&& f) const {
    for (const Section& sec : sections_) {
      if (!sec.each.empty()) {
        for (const auto& [block, local] : sec.each) f(block, local);
      } else {
        for (std::int64_t k = 0; k <= sec.end - sec.start; ++k) f(sec.block, sec.first + k);
      }
    }
  }

 private:
  std::vector<Section> sections_;
};

class CgnsReader {
 public:
  explicit CgnsReader(const std::filesystem::path& file) : file_(file), cgns_(file, CG_MODE_READ) {}

  /// After read(): the mesh node of each vertex of each zone (file order; 0-based, a structured
  /// zone's i fastest).
  [[nodiscard]] const std::vector<std::vector<Index>>& zone_nodes() const noexcept { return zone_nodes_; }

  [[nodiscard]] RawMesh read() {
    const int fn = cgns_.id();
    int nbases = 0;
    cgns_.check(cgns_api().cg_nbases(fn, &nbases), "/");
    if (nbases == 0) cgns_.fail("/", "no CGNS base (expected one CGNSBase_t)");
    char name[33] = {};
    int cell_dim = 0, phys_dim = 0;
    if (nbases > 1) {
      std::string names;
      for (int b = 1; b <= nbases; ++b) {
        cgns_.check(cgns_api().cg_base_read(fn, b, name, &cell_dim, &phys_dim), "/");
        names += (b > 1 ? ", " : "") + std::string(name);
      }
      cgns_.fail("/", std::to_string(nbases) + " bases (" + names + "): meshmotion reads files with one base");
    }
    cgns_.check(cgns_api().cg_base_read(fn, 1, name, &cell_dim, &phys_dim), "/");
    base_ = "/" + std::string(name);
    if (cell_dim != 2 && cell_dim != 3)
      cgns_.fail(base_, "cell dimension " + std::to_string(cell_dim) + " (expected 2 or 3)");
    if (phys_dim < cell_dim || phys_dim > 3)
      cgns_.fail(base_, "physical dimension " + std::to_string(phys_dim) + " for cell dimension " + std::to_string(cell_dim));
    cell_dim_ = cell_dim;
    phys_dim_ = phys_dim;
    raw_.dim = cell_dim;

    int nzones = 0;
    cgns_.check(cgns_api().cg_nzones(fn, 1, &nzones), base_);
    if (nzones == 0) cgns_.fail(base_, "no zone");
    multi_zone_ = nzones > 1;
    for (int z = 1; z <= nzones; ++z) {
      CGNS_ENUMT(ZoneType_t) type{};
      cgns_.check(cgns_api().cg_zone_type(fn, 1, z, &type), base_);
      if (type == CGNS_ENUMV(Structured))
        read_structured_zone(z);
      else if (type == CGNS_ENUMV(Unstructured))
        read_zone(z);
      else
        cgns_.fail(base_, "zone " + std::to_string(z) + " is neither structured nor unstructured");
    }
    return std::move(raw_);
  }

 private:
  void read_zone(int z) {
    const int fn = cgns_.id();
    char name[33] = {};
    cgsize_t size[3] = {};
    cgns_.check(cgns_api().cg_zone_read(fn, 1, z, name, size), base_);
    zone_name_ = name;
    zone_ = base_ + "/" + zone_name_;
    const auto num_vertices = static_cast<std::int64_t>(size[0]);
    const std::vector<Index>& node_of_vertex = zone_nodes_.emplace_back(read_coordinates(z, {num_vertices}));

    int nsections = 0;
    cgns_.check(cgns_api().cg_nsections(fn, 1, z, &nsections), zone_);
    CgnsSections sections;
    bool has_facets = false;
    std::int64_t largest = 0;
    for (int s = 1; s <= nsections; ++s) {
      const std::int64_t last = read_section(z, s, node_of_vertex, num_vertices, sections, has_facets);
      largest = std::max(largest, last);
    }
    sections.finish(cgns_);
    read_bocos(z, sections, node_of_vertex, has_facets);
    // Facets no BC holds keep their section's group.
    for (const auto& [block, local, tag] : section_tags_) {
      int& t = raw_.blocks[block].tags[static_cast<std::size_t>(local)];
      if (t == 0) t = tag;
    }
    section_tags_.clear();
    finish_zone(largest);
  }

  /// Boundary facets made for vertex BCs join the mesh (those a BC holds), numbered after the
  /// zone's `last` element; the next zone's numbers follow.
  void finish_zone(std::int64_t last) {
    for (ElementBlock& src : boundary_)
      for (Index e = 0; e < src.size(); ++e)
        if (const int t = src.tags[static_cast<std::size_t>(e)]; t != 0) {
          ElementBlock& dst = raw_.block(src.type);
          dst.add(src.element(e), t);
          dst.ids.push_back(element_offset_ + ++last);
        }
    boundary_.clear();
    element_offset_ += last;
  }

  /// A structured zone (ni × nj [× nk] vertices, i fastest): its cells as quadrilaterals or
  /// hexahedra, its BCs (vertex or face ranges or lists of i, j, k) as facet groups on the
  /// block's faces; block interfaces join as the nodes of several zones do, by their
  /// coordinates, and the block's 1-to-1 connections with itself (a C-grid's wake cut, an
  /// O-grid's seam) by its connectivity records.
  void read_structured_zone(int z) {
    const int fn = cgns_.id();
    char name[33] = {};
    cgsize_t size[9] = {};
    cgns_.check(cgns_api().cg_zone_read(fn, 1, z, name, size), base_);
    zone_name_ = name;
    zone_ = base_ + "/" + zone_name_;
    std::vector<std::int64_t> n(static_cast<std::size_t>(cell_dim_));
    for (int d = 0; d < cell_dim_; ++d) {
      n[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(size[d]);
      if (n[static_cast<std::size_t>(d)] < 2)
        cgns_.fail(zone_, "structured zone of " + std::to_string(n[static_cast<std::size_t>(d)]) + " vertices along index " +
                              std::to_string(d + 1) + " (expected at least 2)");
    }
    const std::vector<Index>& node_of_vertex = zone_nodes_.emplace_back(read_coordinates(z, n, self_joins(z, n)));
    const std::int64_t ni = n[0], nj = n[1], nk = cell_dim_ == 3 ? n[2] : 2;
    const auto vertex = [&](std::int64_t i, std::int64_t j, std::int64_t k) { return i + ni * (j + nj * k); };
    const ElementType type = cell_dim_ == 3 ? ElementType::hex8 : ElementType::quad4;
    ElementBlock& block = raw_.block(type);
    const auto block_index = static_cast<std::size_t>(&block - raw_.blocks.data());
    const int tag = multi_zone_ ? group_tag(zone_name_, cell_dim_) : 0;
    CgnsSections cells;
    cells.add({zone_, 1, (ni - 1) * (nj - 1) * std::max<std::int64_t>(nk - 1, 1), block_index, block.size(), {}});
    std::int64_t number = 0;
    for (std::int64_t k = 0; k + 1 < nk; ++k)
      for (std::int64_t j = 0; j + 1 < nj; ++j)
        for (std::int64_t i = 0; i + 1 < ni; ++i) {
          std::array<Index, 8> nodes{};
          const std::array<std::int64_t, 8> corners{vertex(i, j, k),         vertex(i + 1, j, k),         vertex(i + 1, j + 1, k),
                                                    vertex(i, j + 1, k),     vertex(i, j, k + 1),         vertex(i + 1, j, k + 1),
                                                    vertex(i + 1, j + 1, k + 1), vertex(i, j + 1, k + 1)};
          const int count = num_nodes(type);
          for (int c = 0; c < count; ++c)
            nodes[static_cast<std::size_t>(c)] = node_of_vertex[static_cast<std::size_t>(corners[static_cast<std::size_t>(c)])];
          block.add(std::span<const Index>(nodes.data(), static_cast<std::size_t>(count)), tag);
          block.ids.push_back(element_offset_ + ++number);
        }
    read_bocos(z, cells, node_of_vertex, false, n);
    finish_zone(number);
  }

  /// A structured zone's 1-to-1 connection with itself: pairs of its vertices (0-based, i
  /// fastest) that are one node when they coincide.
  struct SelfJoin {
    std::string path;
    std::vector<std::pair<std::int64_t, std::int64_t>> pairs;
  };

  /// The 1-to-1 connections of structured zone z (vertices per index `n`) whose donor is the
  /// zone itself, each vertex of the range paired with its donor vertex through the
  /// connection's transform (SIDS: donor = T (index − range begin) + donor begin). Refuses a
  /// range or transform that does not fit the zone.
  [[nodiscard]] std::vector<SelfJoin> self_joins(int z, const std::vector<std::int64_t>& n) {
    const int fn = cgns_.id();
    int count = 0;
    cgns_.check(cgns_api().cg_n1to1(fn, 1, z, &count), zone_ + "/ZoneGridConnectivity");
    std::vector<SelfJoin> out;
    const std::size_t dim = n.size();
    for (int c = 1; c <= count; ++c) {
      char name[33] = {}, donor[33] = {};
      std::array<cgsize_t, 6> range{}, donor_range{};
      std::array<int, 3> transform{};
      cgns_.check(cgns_api().cg_1to1_read(fn, 1, z, c, name, donor, range.data(), donor_range.data(), transform.data()),
                  zone_ + "/ZoneGridConnectivity");
      if (std::string(donor) != zone_name_) continue;  // another zone: joined by coordinates
      SelfJoin& join = out.emplace_back();
      join.path = zone_ + "/ZoneGridConnectivity/" + name;
      std::array<bool, 3> used{};
      for (std::size_t a = 0; a < dim; ++a) {
        const int t = transform[a];
        const auto to = static_cast<std::size_t>(std::abs(t) - 1);
        if (t == 0 || std::abs(t) > static_cast<int>(dim) || used[to])
          cgns_.fail(join.path, "transform (" + std::to_string(transform[0]) + ", " + std::to_string(transform[1]) +
                                    (dim == 3 ? ", " + std::to_string(transform[2]) : std::string()) +
                                    ") is not a signed permutation of the indices");
        used[to] = true;
      }
      const auto inside = [&](const std::array<cgsize_t, 6>& r, std::size_t d, std::int64_t v) {
        return v >= std::min(r[d], r[dim + d]) && v <= std::max(r[d], r[dim + d]) && v >= 1 && v <= n[d];
      };
      const auto check = [&](std::size_t d, std::int64_t v) {
        if (v < 1 || v > n[d])
          cgns_.fail(join.path, "range index " + std::to_string(d + 1) + " is " + std::to_string(v) + " (the zone has " +
                                    std::to_string(n[d]) + " vertices along it, numbered from 1)");
      };
      const std::vector<cgsize_t> corners(range.begin(), range.begin() + static_cast<std::ptrdiff_t>(2 * dim));
      for_each_index(corners, true, dim, check, [&](const std::array<std::int64_t, 3>& p) {
        std::array<std::int64_t, 3> q{1, 1, 1};
        for (std::size_t a = 0; a < dim; ++a) {
          const auto to = static_cast<std::size_t>(std::abs(transform[a]) - 1);
          q[to] = donor_range[to] + (transform[a] > 0 ? 1 : -1) * (p[a] - range[a]);
        }
        for (std::size_t d = 0; d < dim; ++d)
          if (!inside(donor_range, d, q[d]))
            cgns_.fail(join.path, "vertex (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) +
                                      (dim == 3 ? ", " + std::to_string(p[2]) : std::string()) +
                                      ") maps outside the donor range (its transform and ranges disagree)");
        join.pairs.emplace_back(vertex_number(p, n), vertex_number(q, n));
      });
    }
    return out;
  }

  /// Reads the zone's coordinates (`size`: its vertices, or per index of a structured zone);
  /// returns the mesh node of each CGNS vertex (0-based, i fastest). The vertices a self join
  /// pairs are one node where every pair of that join coincides (to 1e-9 of the zone's size; a
  /// periodic connection, whose vertices are apart, joins nothing).
  [[nodiscard]] std::vector<Index> read_coordinates(int z, const std::vector<std::int64_t>& size,
                                                    const std::vector<SelfJoin>& joins = {}) {
    std::int64_t num_vertices = 1;
    for (const std::int64_t extent : size) num_vertices *= extent;
    const int fn = cgns_.id();
    const std::string path = zone_ + "/GridCoordinates";
    int ncoords = 0;
    cgns_.check(cgns_api().cg_ncoords(fn, 1, z, &ncoords), path);
    static constexpr const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    std::vector<std::string> present;
    for (int c = 1; c <= ncoords; ++c) {
      CGNS_ENUMT(DataType_t) type{};
      char cname[33] = {};
      cgns_.check(cgns_api().cg_coord_info(fn, 1, z, c, &type, cname), path);
      present.emplace_back(cname);
    }
    std::vector<double> xyz(static_cast<std::size_t>(3 * num_vertices), 0.0);
    std::vector<double> column(static_cast<std::size_t>(num_vertices));
    for (int d = 0; d < phys_dim_; ++d) {
      if (std::find(present.begin(), present.end(), names[d]) == present.end()) {
        std::string have;
        for (const auto& p : present) have += (have.empty() ? "" : ", ") + p;
        cgns_.fail(path, std::string("no ") + names[d] + " (has: " + (have.empty() ? "none" : have) +
                             "; meshmotion reads Cartesian coordinates)");
      }
      std::array<cgsize_t, 3> lo{1, 1, 1}, hi{};
      for (std::size_t i = 0; i < size.size(); ++i) hi[i] = static_cast<cgsize_t>(size[i]);
      if (num_vertices > 0)
        cgns_.check(cgns_api().cg_coord_read(fn, 1, z, names[d], CGNS_ENUMV(RealDouble), lo.data(), hi.data(), column.data()),
                    path + "/" + names[d]);
      for (std::int64_t i = 0; i < num_vertices; ++i) xyz[static_cast<std::size_t>(3 * i + d)] = column[static_cast<std::size_t>(i)];
    }
    std::vector<Index> node(static_cast<std::size_t>(num_vertices));
    const Index first = raw_.num_nodes();
    const std::vector<std::int64_t> same = joined_vertices(xyz, joins);
    if (!multi_zone_ && same.empty()) {
      raw_.coords = std::move(xyz);
      for (std::int64_t i = 0; i < num_vertices; ++i) node[static_cast<std::size_t>(i)] = first + i;
      return node;
    }
    // Conforming zone interfaces: the same coordinates in an earlier zone are the same node
    // (not within one zone: duplicated nodes there are the file's, kept apart unless joined).
    std::vector<std::pair<Key, Index>> added;
    for (std::int64_t i = 0; i < num_vertices; ++i) {
      if (!same.empty() && same[static_cast<std::size_t>(i)] != i) {
        node[static_cast<std::size_t>(i)] = node[static_cast<std::size_t>(same[static_cast<std::size_t>(i)])];
        continue;
      }
      if (multi_zone_) {
        const Key key = key_of(&xyz[static_cast<std::size_t>(3 * i)]);
        if (const auto it = node_at_.find(key); it != node_at_.end()) {
          node[static_cast<std::size_t>(i)] = it->second;
          continue;
        }
        added.emplace_back(key, raw_.num_nodes());
      }
      node[static_cast<std::size_t>(i)] = raw_.num_nodes();
      raw_.coords.insert(raw_.coords.end(), xyz.begin() + 3 * i, xyz.begin() + 3 * i + 3);
    }
    for (const auto& [key, index] : added) node_at_.try_emplace(key, index);
    return node;
  }

  /// Per vertex of `xyz` (3 per vertex), the first vertex it is one node with through `joins`
  /// (itself when none); empty when no join applies.
  [[nodiscard]] static std::vector<std::int64_t> joined_vertices(const std::vector<double>& xyz, const std::vector<SelfJoin>& joins) {
    if (joins.empty()) return {};
    const auto count = static_cast<std::int64_t>(xyz.size() / 3);
    std::array<double, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (std::int64_t v = 0; v < count; ++v)
      for (std::size_t d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], xyz[static_cast<std::size_t>(3 * v) + d]);
        hi[d] = std::max(hi[d], xyz[static_cast<std::size_t>(3 * v) + d]);
      }
    double diagonal = 0.0;
    for (std::size_t d = 0; d < 3; ++d) diagonal += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    const double tolerance = 1e-9 * std::sqrt(diagonal);
    const auto apart = [&](std::int64_t a, std::int64_t b) {
      double d2 = 0.0;
      for (std::size_t d = 0; d < 3; ++d) {
        const double e = xyz[static_cast<std::size_t>(3 * a) + d] - xyz[static_cast<std::size_t>(3 * b) + d];
        d2 += e * e;
      }
      return d2 > tolerance * tolerance;
    };
    std::vector<std::int64_t> root(static_cast<std::size_t>(count));
    std::iota(root.begin(), root.end(), std::int64_t{0});
    const auto find = [&](std::int64_t v) {
      while (root[static_cast<std::size_t>(v)] != v) v = root[static_cast<std::size_t>(v)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(v)])];
      return v;
    };
    bool any = false;
    for (const SelfJoin& join : joins) {
      if (std::any_of(join.pairs.begin(), join.pairs.end(), [&](const auto& p) { return apart(p.first, p.second); })) continue;
      for (const auto& [a, b] : join.pairs) {
        const std::int64_t ra = find(a), rb = find(b);
        if (ra != rb) root[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
        any = any || ra != rb;
      }
    }
    if (!any) return {};
    for (std::int64_t v = 0; v < count; ++v) root[static_cast<std::size_t>(v)] = find(v);
    return root;
  }

  /// Reads section s into the blocks; returns its last element number (zone numbering).
  std::int64_t read_section(int z, int s, const std::vector<Index>& node_of_vertex, std::int64_t num_vertices,
                            CgnsSections& sections, bool& has_facets) {
    const int fn = cgns_.id();
    char name[33] = {};
    CGNS_ENUMT(ElementType_t) type{};
    cgsize_t start = 0, end = 0;
    int nbndry = 0, parent_flag = 0;
    cgns_.check(cgns_api().cg_section_read(fn, 1, z, s, name, &type, &start, &end, &nbndry, &parent_flag), zone_);
    const std::string path = zone_ + "/" + name;
    if (end < start) cgns_.fail(path, "element range " + std::to_string(start) + ".." + std::to_string(end) + " is empty or reversed");
    const std::int64_t count = static_cast<std::int64_t>(end) - start + 1;
    if (type == CGNS_ENUMV(NGON_n) || type == CGNS_ENUMV(NFACE_n))
      cgns_.fail(path, cgns_type_name(type) + " section: polyhedral cells are not supported (expected standard element types)");
    cgsize_t data_size = 0;
    cgns_.check(cgns_api().cg_ElementDataSize(fn, 1, z, s, &data_size), path);
    std::vector<cgsize_t> data(static_cast<std::size_t>(data_size));
    std::vector<cgsize_t> offsets;
    const bool mixed = type == CGNS_ENUMV(MIXED);
    if (mixed) {
      offsets.resize(static_cast<std::size_t>(count + 1));
      cgns_.check(cgns_api().cg_poly_elements_read(fn, 1, z, s, data.data(), offsets.data(), nullptr), path + "/ElementConnectivity");
    } else {
      cgns_.check(cgns_api().cg_elements_read(fn, 1, z, s, data.data(), nullptr), path + "/ElementConnectivity");
    }
    // The section's group per element dimension: none when the section is named after its
    // element type (as write_cgns names elements without a group); the zone's for cells of
    // a multi-zone file.
    const bool unnamed = std::string(name) == cgns_type_name(type);
    std::array<int, 4> tag_of_dim{-1, -1, -1, -1};
    const auto tag_for = [&](int d) {
      int& t = tag_of_dim[static_cast<std::size_t>(d)];
      if (t < 0) t = multi_zone_ && d == cell_dim_ ? group_tag(zone_name_, d) : unnamed ? 0 : group_tag(name, d);
      return t;
    };
    CgnsSections::Section section{path, start, end, 0, 0, {}};
    ElementType current{};
    ElementBlock* block = nullptr;
    std::size_t block_index = 0;
    const auto use_type = [&](CGNS_ENUMT(ElementType_t) t, std::int64_t number) {
      const int ours = element_type_of_cgns(t);
      if (ours < 0) {
        const bool high_order = static_cast<int>(t) >= static_cast<int>(CGNS_ENUMV(BAR_4));  // BAR_4 and after: order 3 and 4
        cgns_.fail(path, "element " + std::to_string(number) + " is " + cgns_type_name(t) +
                             (high_order ? " (meshmotion reads the complete Lagrange elements: no serendipity ones past order 2)"
                                        : " (not supported)"));
      }
      current = static_cast<ElementType>(ours);
      block = &raw_.block(current);
      block_index = static_cast<std::size_t>(block - raw_.blocks.data());
    };
    if (!mixed) {
      use_type(type, start);
      section.block = block_index;
      section.first = block->size();
      block->reserve(block->size() + count);
      block->ids.reserve(block->ids.size() + static_cast<std::size_t>(count));
    } else {
      section.each.reserve(static_cast<std::size_t>(count));
    }
    std::size_t at = 0;
    for (std::int64_t e = 0; e < count; ++e) {
      const std::int64_t number = start + e;
      if (mixed) {
        at = static_cast<std::size_t>(offsets[static_cast<std::size_t>(e)]);
        if (at >= data.size()) cgns_.fail(path, "element " + std::to_string(number) + ": offset past the connectivity");
        const auto t = static_cast<CGNS_ENUMT(ElementType_t)>(data[at++]);
        if (block == nullptr || cgns_type(current) != t) use_type(t, number);
      }
      const int n = num_nodes(current);
      if (at + static_cast<std::size_t>(n) > data.size())
        cgns_.fail(path, "element " + std::to_string(number) + ": connectivity ends inside it");
      const std::vector<int>& order = cgns_order_of(current);
      const Index local = block->size();
      block->connectivity.resize(block->connectivity.size() + static_cast<std::size_t>(n));
      Index* nodes = block->connectivity.data() + local * n;
      for (int k = 0; k < n; ++k) {
        const auto v = static_cast<std::int64_t>(data[at + static_cast<std::size_t>(k)]);
        if (v < 1 || v > num_vertices)
          cgns_.fail(path, "element " + std::to_string(number) + " has node " + std::to_string(v) + " (the zone has " +
                               std::to_string(num_vertices) + " nodes, numbered from 1)");
        nodes[order[static_cast<std::size_t>(k)]] = node_of_vertex[static_cast<std::size_t>(v - 1)];
      }
      // Cells and facets through a node twice are refused; lower elements (a degenerate edge) are not kept.
      if (dimension(current) >= cell_dim_ - 1)
        if (const auto twice = repeated_node(data.data() + at, n))
          cgns_.fail(path, "element " + std::to_string(number) + " lists node " + std::to_string(*twice) + " twice");
      at += static_cast<std::size_t>(n);
      block->ids.push_back(number + element_offset_);
      const int d = dimension(current);
      if (d == cell_dim_ - 1) {
        has_facets = true;
        block->tags.push_back(0);  // a BC may claim it; else its section's group
        section_tags_.push_back({block_index, local, tag_for(d)});
      } else {
        block->tags.push_back(tag_for(d));
      }
      if (mixed) section.each.emplace_back(block_index, local);
    }
    sections.add(std::move(section));
    return end;
  }

  /// The zone's BCs as facet groups. `structured`: the vertices per index of a structured zone,
  /// whose BCs are vertex ranges or lists of (i, j[, k]); empty for an unstructured one.
  void read_bocos(int z, const CgnsSections& sections, const std::vector<Index>& node_of_vertex, bool has_facets,
                  const std::vector<std::int64_t>& structured = {}) {
    const int fn = cgns_.id();
    int nbocos = 0;
    cgns_.check(cgns_api().cg_nbocos(fn, 1, z, &nbocos), zone_ + "/ZoneBC");
    for (int bc = 1; bc <= nbocos; ++bc) {
      char name[33] = {};
      CGNS_ENUMT(BCType_t) bctype{};
      CGNS_ENUMT(PointSetType_t) ptset{};
      cgsize_t npnts = 0, normal_size = 0;
      int normal_index[3] = {};
      CGNS_ENUMT(DataType_t) normal_type{};
      int ndataset = 0;
      cgns_.check(cgns_api().cg_boco_info(fn, 1, z, bc, name, &bctype, &ptset, &npnts, normal_index, &normal_size, &normal_type, &ndataset),
                  zone_ + "/ZoneBC");
      const std::string path = zone_ + "/ZoneBC/" + name;
      CGNS_ENUMT(GridLocation_t) location = CGNS_ENUMV(Vertex);
      cgns_.check(cgns_api().cg_boco_gridlocation_read(fn, 1, z, bc, &location), path);
      const auto index_dim = structured.empty() ? std::size_t{1} : structured.size();
      std::vector<cgsize_t> points(index_dim * static_cast<std::size_t>(std::max<cgsize_t>(npnts, 0)));
      if (npnts > 0) cgns_.check(cgns_api().cg_boco_read(fn, 1, z, bc, points.data(), nullptr), path);
      std::string group = name;
      char family[33] = {};
      if (cgns_api().cg_goto(fn, 1, "Zone_t", z, "ZoneBC_t", 1, "BC_t", bc, "end") == CG_OK && cgns_api().cg_famname_read(family) == CG_OK)
        group = family;
      const int tag = group_tag(group, cell_dim_ - 1);

      const bool range = ptset == CGNS_ENUMV(PointRange) || ptset == CGNS_ENUMV(ElementRange);
      const bool list = ptset == CGNS_ENUMV(PointList) || ptset == CGNS_ENUMV(ElementList);
      if (!range && !list) cgns_.fail(path, "point set type " + std::to_string(static_cast<int>(ptset)) +
                                                " (expected PointList, PointRange, ElementList or ElementRange)");
      if (range && points.size() != 2 * index_dim)
        cgns_.fail(path, "a range needs " + std::to_string(2 * index_dim) + " numbers (got " + std::to_string(points.size()) + ")");
      if (!structured.empty()) {
        if (ptset == CGNS_ENUMV(ElementRange) || ptset == CGNS_ENUMV(ElementList))
          cgns_.fail(path, "a structured zone's BC by element numbers (expected a PointRange or PointList of indices)");
        if (location == CGNS_ENUMV(Vertex))
          tag_facets_on_vertices(structured_bc_vertices(points, range, structured, path), node_of_vertex, tag, path, false, sections);
        else
          tag_structured_faces(structured_bc_faces(points, range, structured, location, path), node_of_vertex, tag, path, sections);
        continue;
      }
      const bool elements = ptset == CGNS_ENUMV(ElementRange) || ptset == CGNS_ENUMV(ElementList) ||
                            location != CGNS_ENUMV(Vertex);
      const auto for_each_number = [&](auto&& f) {
        if (range)
          for (std::int64_t k = points[0]; k <= points[1]; ++k) f(k);
        else
          for (const cgsize_t k : points) f(static_cast<std::int64_t>(k));
      };
      if (elements) {
        for_each_number([&](std::int64_t number) {
          std::size_t block = 0;
          Index local = 0;
          if (!sections.find(number, block, local)) cgns_.fail(path, "element " + std::to_string(number) + " is in no section of the zone");
          claim(block, local, tag, path);
        });
      } else {
        std::vector<char> in_bc(node_of_vertex.size(), 0);
        for_each_number([&](std::int64_t v) {
          if (v < 1 || v > static_cast<std::int64_t>(node_of_vertex.size()))
            cgns_.fail(path, "node " + std::to_string(v) + " is out of range (the zone has " +
                                 std::to_string(node_of_vertex.size()) + " nodes, numbered from 1)");
          in_bc[static_cast<std::size_t>(v - 1)] = 1;
        });
        tag_facets_on_vertices(in_bc, node_of_vertex, tag, path, has_facets, sections);
      }
    }
  }

  /// Calls visit(ijk) for each index (i, j[, k]) of a point set of a `dim`-index zone: a list
  /// (dim numbers per point) or the box between a range's two corners, in any order; check(d, v)
  /// sees each number given first.
  template <class Check, class Visit>
  static void for_each_index(const std::vector<cgsize_t>& points, bool range, std::size_t dim, Check&& check, Visit&& visit) {
    if (!range) {
      for (std::size_t p = 0; p + dim <= points.size(); p += dim) {
        std::array<std::int64_t, 3> ijk{1, 1, 1};
        for (std::size_t d = 0; d < dim; ++d) check(d, ijk[d] = points[p + d]);
        visit(ijk);
      }
      return;
    }
    std::array<std::int64_t, 3> lo{1, 1, 1}, hi{1, 1, 1};
    for (std::size_t d = 0; d < dim; ++d) {
      check(d, points[d]);
      check(d, points[dim + d]);
      lo[d] = std::min<std::int64_t>(points[d], points[dim + d]);
      hi[d] = std::max<std::int64_t>(points[d], points[dim + d]);
    }
    for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
        for (std::int64_t i = lo[0]; i <= hi[0]; ++i) visit(std::array<std::int64_t, 3>{i, j, k});
  }

  /// The 0-based number (i fastest) of vertex ijk (1-based) of a zone with n vertices per index.
  [[nodiscard]] static std::int64_t vertex_number(const std::array<std::int64_t, 3>& ijk, const std::vector<std::int64_t>& n) {
    std::int64_t at = 0;
    for (std::size_t d = n.size(); d-- > 0;) at = at * n[d] + ijk[d] - 1;
    return at;
  }

  /// The vertices (flags, i fastest) of a structured BC: the box between a range's two
  /// corners, or the listed (i, j[, k]), each index within the zone.
  std::vector<char> structured_bc_vertices(const std::vector<cgsize_t>& points, bool range, const std::vector<std::int64_t>& n,
                                           const std::string& path) const {
    const std::size_t dim = n.size();
    std::int64_t total = 1;
    for (const std::int64_t extent : n) total *= extent;
    std::vector<char> in_bc(static_cast<std::size_t>(total), 0);
    const auto check = [&](std::size_t d, std::int64_t v) {
      if (v < 1 || v > n[d])
        cgns_.fail(path, "index " + std::to_string(d + 1) + " is " + std::to_string(v) + " (the zone has " + std::to_string(n[d]) +
                             " vertices along it, numbered from 1)");
    };
    const auto flag = [&](const std::array<std::int64_t, 3>& ijk) { in_bc[static_cast<std::size_t>(vertex_number(ijk, n))] = 1; };
    for_each_index(points, range, dim, check, flag);
    return in_bc;
  }

  /// The faces of a structured BC located at faces, each as its vertices (0-based, i fastest;
  /// 2 in 2D, 4 in 3D): a range or list of face indices, the index normal to the faces taking
  /// vertex values (1..n) and the others cell values (1..n−1), as SIDS numbers them. The normal
  /// index is the location's (IFaceCenter, JFaceCenter, KFaceCenter) or, for FaceCenter (and a
  /// 2D block's EdgeCenter), the one a range holds at the block's first or last vertex plane.
  std::vector<std::array<std::int64_t, 4>> structured_bc_faces(const std::vector<cgsize_t>& points, bool range,
                                                                const std::vector<std::int64_t>& n,
                                                                CGNS_ENUMT(GridLocation_t) location, const std::string& path) const {
    const std::size_t dim = n.size();
    int normal = -1;
    // A 2D block's faces are its edges: CGNS writes their BCs at EdgeCenter.
    const bool faces = location == CGNS_ENUMV(FaceCenter) || (dim == 2 && location == CGNS_ENUMV(EdgeCenter));
    if (location == CGNS_ENUMV(IFaceCenter)) normal = 0;
    else if (location == CGNS_ENUMV(JFaceCenter)) normal = 1;
    else if (location == CGNS_ENUMV(KFaceCenter) && dim == 3) normal = 2;
    else if (!faces)
      cgns_.fail(path, "a structured zone's BC located at cells or edges (expected Vertex, FaceCenter, IFaceCenter, "
                       "JFaceCenter, KFaceCenter, or EdgeCenter in 2D)");
    if (normal < 0) {
      if (!range) cgns_.fail(path, "a FaceCenter or EdgeCenter PointList does not say which index is normal to its faces "
                                   "(give IFaceCenter, JFaceCenter or KFaceCenter, or a PointRange)");
      for (std::size_t d = 0; d < dim; ++d)
        if (points[d] == points[dim + d] && (points[d] == 1 || points[d] == n[d])) {
          if (normal >= 0)
            cgns_.fail(path, "the face range lies on two block faces (indices " + std::to_string(normal + 1) + " and " +
                                 std::to_string(d + 1) + "): give IFaceCenter, JFaceCenter or KFaceCenter");
          normal = static_cast<int>(d);
        }
      if (normal < 0) cgns_.fail(path, "the face range lies on no block face (expected one index fixed at 1 or at its last vertex)");
    }
    const auto check = [&](std::size_t d, std::int64_t v) {
      const std::int64_t last = static_cast<int>(d) == normal ? n[d] : n[d] - 1;
      if (v < 1 || v > last)
        cgns_.fail(path, "face index " + std::to_string(d + 1) + " is " + std::to_string(v) + " (expected 1 to " +
                             std::to_string(last) + " for " + (static_cast<int>(d) == normal ? "vertex planes" : "cells") +
                             " along it)");
    };
    std::vector<std::array<std::int64_t, 4>> out;
    const auto add = [&](const std::array<std::int64_t, 3>& f) {
      std::array<std::int64_t, 4> face{-1, -1, -1, -1};
      const std::size_t corners = std::size_t{1} << (dim - 1);
      for (std::size_t c = 0; c < corners; ++c) {
        std::array<std::int64_t, 3> v = f;
        std::size_t bit = 0;
        for (std::size_t d = 0; d < dim; ++d)
          if (static_cast<int>(d) != normal) v[d] += static_cast<std::int64_t>((c >> bit++) & 1U);
        face[c] = vertex_number(v, n);
      }
      out.push_back(face);
    };
    for_each_index(points, range, dim, check, add);
    return out;
  }

  /// A face BC of a structured zone: each face (its vertices) is the boundary facet with those
  /// nodes; a face inside the block is refused.
  void tag_structured_faces(const std::vector<std::array<std::int64_t, 4>>& faces, const std::vector<Index>& node_of_vertex,
                            int tag, const std::string& path, const CgnsSections& sections) {
    if (boundary_.empty()) boundary_ = cell_dim_ == 3 ? zone_boundary<3>(sections) : zone_boundary<2>(sections);
    const auto sorted = [](std::array<Index, 4> key) {
      std::sort(key.begin(), key.end());
      return key;
    };
    std::map<std::array<Index, 4>, std::pair<std::size_t, Index>> facet_at;
    for (std::size_t k = 0; k < boundary_.size(); ++k)
      for (Index e = 0; e < boundary_[k].size(); ++e) {
        std::array<Index, 4> key{-1, -1, -1, -1};
        const auto nodes = boundary_[k].element(e);
        std::copy_n(nodes.begin(), std::min<std::size_t>(nodes.size(), 4), key.begin());
        facet_at.emplace(sorted(key), std::pair{k, e});
      }
    for (const auto& face : faces) {
      std::array<Index, 4> key{-1, -1, -1, -1};
      for (std::size_t c = 0; c < 4 && face[c] >= 0; ++c) key[c] = node_of_vertex[static_cast<std::size_t>(face[c])];
      const auto found = facet_at.find(sorted(key));
      if (found == facet_at.end())
        cgns_.fail(path, "a face of the BC (vertex " + std::to_string(face[0] + 1) + " of the zone, counted i fastest from 1) is "
                         "not on the block's boundary");
      int& t = boundary_[found->second.first].tags[static_cast<std::size_t>(found->second.second)];
      if (t != 0 && t != tag) cgns_.fail(path, "a boundary facet lies in two BCs (the groups of tags " + std::to_string(t) +
                                                   " and " + std::to_string(tag) + ")");
      t = tag;
    }
  }

  /// A vertex BC: the zone's facets whose vertices the BC all holds; its boundary facets when
  /// the zone has no facet section.
  void tag_facets_on_vertices(const std::vector<char>& in_bc, const std::vector<Index>& node_of_vertex, int tag,
                              const std::string& path, bool has_facets, const CgnsSections& sections) {
    std::vector<char> marked(static_cast<std::size_t>(raw_.num_nodes()), 0);
    for (std::size_t v = 0; v < in_bc.size(); ++v)
      if (in_bc[v]) marked[static_cast<std::size_t>(node_of_vertex[v])] = 1;
    const auto all_marked = [&](std::span<const Index> nodes, ElementType t) {
      for (int k = 0; k < num_vertices(t); ++k)
        if (!marked[static_cast<std::size_t>(nodes[static_cast<std::size_t>(k)])]) return false;
      return true;
    };
    if (has_facets) {
      for (const auto& [block, local, section_tag] : section_tags_) {
        const ElementBlock& b = raw_.blocks[block];
        if (all_marked(b.element(local), b.type)) claim(block, local, tag, path);
      }
      return;
    }
    if (boundary_.empty()) boundary_ = cell_dim_ == 3 ? zone_boundary<3>(sections) : zone_boundary<2>(sections);
    for (std::size_t k = 0; k < boundary_.size(); ++k) {
      ElementBlock& src = boundary_[k];
      for (Index e = 0; e < src.size(); ++e) {
        if (!all_marked(src.element(e), src.type)) continue;
        int& t = src.tags[static_cast<std::size_t>(e)];
        if (t != 0 && t != tag) cgns_.fail(path, "a boundary facet lies in two vertex BCs (the groups of tags " + std::to_string(t) +
                                                     " and " + std::to_string(tag) + ")");
        t = tag;
      }
    }
  }

  /// The boundary facets of this zone's cells (topology only: the coordinates are not used).
  template <int Dim>
  [[nodiscard]] std::vector<ElementBlock> zone_boundary(const CgnsSections& sections) const {
    Mesh<Dim> cells;
    cells.points = Points<Dim>::Zero(Dim, raw_.num_nodes());
    sections.for_each([&](std::size_t block, Index local) {
      const ElementBlock& b = raw_.blocks[block];
      if (dimension(b.type) == Dim) cells.block(b.type).add(b.element(local));
    });
    return boundary_facets(cells);
  }

  /// Gives element (block, local) the BC tag; refuses an element two BCs claim.
  void claim(std::size_t block, Index local, int tag, const std::string& path) {
    int& t = raw_.blocks[block].tags[static_cast<std::size_t>(local)];
    const bool facet = dimension(raw_.blocks[block].type) == cell_dim_ - 1;
    if (facet && t != 0 && t != tag) {
      std::string other;
      for (const auto& g : raw_.groups)
        if (g.tag == t) other = g.name;
      cgns_.fail(path, "element " + std::to_string(raw_.blocks[block].ids[static_cast<std::size_t>(local)] - element_offset_) +
                           " is also in BC '" + other + "'");
    }
    t = tag;
  }

  /// The tag of group (name, dim), created on first use.
  int group_tag(const std::string& name, int dim) {
    const auto key = std::make_pair(dim, name);
    const auto it = tags_.find(key);
    if (it != tags_.end()) return it->second;
    const int tag = static_cast<int>(tags_.size()) + 1;
    tags_.emplace(key, tag);
    raw_.groups.push_back(PhysicalGroup{dim, tag, name});
    return tag;
  }

  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const noexcept {
      return static_cast<std::size_t>((k[0] * 0x9E3779B97F4A7C15ull) ^ (k[1] * 0xC2B2AE3D27D4EB4Full) ^ (k[2] * 0x165667B19E3779F9ull));
    }
  };
  [[nodiscard]] static Key key_of(const double* c) {
    Key k{};
    for (int d = 0; d < 3; ++d) {
      const double v = c[d] == 0.0 ? 0.0 : c[d];  // -0 and +0 are one place
      std::memcpy(&k[static_cast<std::size_t>(d)], &v, sizeof v);
    }
    return k;
  }

  struct SectionTag {
    std::size_t block;
    Index local;
    int tag;
  };

  std::filesystem::path file_;
  CgnsFile cgns_;
  RawMesh raw_;
  std::string base_, zone_, zone_name_;
  int cell_dim_ = 3, phys_dim_ = 3;
  bool multi_zone_ = false;
  std::int64_t element_offset_ = 0;
  std::map<std::pair<int, std::string>, int> tags_;
  std::vector<SectionTag> section_tags_;
  std::unordered_map<Key, Index, KeyHash> node_at_;
  std::vector<ElementBlock> boundary_;
  std::vector<std::vector<Index>> zone_nodes_;
};

}  // namespace detail

#endif  // MESHMOTION_HAVE_CGNS

/// Reads a .cgns file (see the file comment for what is read and what is refused). Throws
/// IoError for a file the CGNS library cannot open or read, InputError naming the CGNS node
/// path for content meshmotion does not take, and InputError when built without CGNS.
[[nodiscard]] inline AnyMesh read_cgns(const std::filesystem::path& file) {
#ifdef MESHMOTION_HAVE_CGNS
  detail::check_regular_file(file);
  return detail::to_any_mesh(detail::CgnsReader(file).read(), file);
#else
  throw InputError(file.string() + ": reading CGNS needs the CGNS library (meshmotion was built without it: install "
                   "libcgns-dev and reconfigure)");
#endif
}

}  // namespace meshmotion
