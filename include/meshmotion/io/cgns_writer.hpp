#pragma once
/// \file
/// CGNS (.cgns) writing through the CGNS library (Debian libcgns-dev; see io/cgns.hpp for the
/// layout written). Without the library write_cgns() throws InputError saying so.

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/core/detail/atomic_file.hpp"
#include "meshmotion/io/cgns_reader.hpp"
#include "meshmotion/io/detail/cgns_file.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <map>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace meshmotion {

#ifdef MESHMOTION_HAVE_CGNS

namespace detail {

/// A name CGNS can hold (at most 32 characters, no '/'), or InputError naming the group.
inline void check_cgns_name(const std::string& name, const std::string& what) {
  if (name.empty() || name.size() > 32 || name.find('/') != std::string::npos || name == "." || name == "..")
    throw InputError("write_cgns: " + what + " '" + name + "' cannot be a CGNS node name (1 to 32 characters, no '/')");
}

template <int Dim>
class CgnsWriter {
 public:
  explicit CgnsWriter(const Mesh<Dim>& mesh) : mesh_(mesh) {
    validate(mesh);
    for (const auto* list : {&mesh.cells, &mesh.facets, &mesh.lower})
      for (const auto& b : *list)
        if (!cgns_writes(b.type))
          throw InputError("write_cgns: " + std::string(name(b.type)) +
                           " elements: CGNS names elements to order 4 (expected .msh or .vtu for higher orders)");
    list_elements();
    plan_sections();
  }

  /// Writes the file at `tmp`, the temporary path of `file` (which errors name).
  void write(const std::filesystem::path& tmp, const std::filesystem::path& file) {
    CgnsFile f(tmp, CG_MODE_WRITE, file);
    const int fn = f.id();
    int B = 0, Z = 0;
    f.check(cgns_api().cg_base_write(fn, "Base", Dim, Dim, &B), "/Base");
    // Coordinates carry the mesh's own length unit, which meshmotion does not know.
    f.check(cgns_api().cg_goto(fn, B, "end"), "/Base");
    f.check(cgns_api().cg_dataclass_write(CGNS_ENUMV(NormalizedByUnknownDimensional)), "/Base/DataClass");
    cgsize_t size[3] = {static_cast<cgsize_t>(mesh_.num_nodes()), static_cast<cgsize_t>(mesh_.num_cells()), 0};
    f.check(cgns_api().cg_zone_write(fn, B, "Zone", size, CGNS_ENUMV(Unstructured), &Z), "/Base/Zone");
    static constexpr const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    std::vector<double> column(static_cast<std::size_t>(mesh_.num_nodes()));
    for (int d = 0; d < Dim; ++d) {
      for (Index i = 0; i < mesh_.num_nodes(); ++i) column[static_cast<std::size_t>(i)] = mesh_.points(d, i);
      int C = 0;
      const std::string path = std::string("/Base/Zone/GridCoordinates/") + names[d];
      f.check(cgns_api().cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), names[d], column.data(), &C), path);
      static constexpr float length[5] = {0.0F, 1.0F, 0.0F, 0.0F, 0.0F};  // mass, length, time, temperature, angle
      f.check(cgns_api().cg_goto(fn, B, "Zone_t", Z, "GridCoordinates_t", 1, "DataArray_t", C, "end"), path);
      f.check(cgns_api().cg_exponents_write(CGNS_ENUMV(RealSingle), length), path + "/DimensionalExponents");
    }
    std::vector<cgsize_t> data, offsets;
    for (const SectionPlan& plan : sections_) {
      data.clear();
      offsets.assign(1, 0);
      for (std::size_t k = plan.begin; k < plan.end; ++k) {
        const Item& item = items_[k];
        const ElementBlock& b = block_of(item);
        if (plan.mixed) data.push_back(static_cast<cgsize_t>(cgns_type(b.type)));
        const auto nodes = b.element(item.local);
        for (const int local : cgns_order_of(b.type)) data.push_back(static_cast<cgsize_t>(nodes[static_cast<std::size_t>(local)] + 1));
        offsets.push_back(static_cast<cgsize_t>(data.size()));
      }
      const auto start = static_cast<cgsize_t>(plan.begin + 1), end = static_cast<cgsize_t>(plan.end);
      int S = 0;
      const std::string path = "/Base/Zone/" + plan.name;
      if (plan.mixed)
        f.check(cgns_api().cg_poly_section_write(fn, B, Z, plan.name.c_str(), CGNS_ENUMV(MIXED), start, end, 0, data.data(), offsets.data(), &S), path);
      else
        f.check(cgns_api().cg_section_write(fn, B, Z, plan.name.c_str(), cgns_type(plan.type), start, end, 0, data.data(), &S), path);
    }
    for (const auto& [name, numbers] : bocos_) {
      int BC = 0;
      const std::string path = "/Base/Zone/ZoneBC/" + name;
      f.check(cgns_api().cg_boco_write(fn, B, Z, name.c_str(), CGNS_ENUMV(BCTypeUserDefined), CGNS_ENUMV(PointList),
                            static_cast<cgsize_t>(numbers.size()), numbers.data(), &BC), path);
      f.check(cgns_api().cg_boco_gridlocation_write(fn, B, Z, BC, Dim == 3 ? CGNS_ENUMV(FaceCenter) : CGNS_ENUMV(EdgeCenter)), path);
    }
    f.close();
  }

 private:
  struct Item {
    std::int64_t key;
    int list;  // 0 cells, 1 facets, 2 lower
    std::size_t block;
    Index local;
  };
  struct SectionPlan {
    std::string name;
    std::size_t begin, end;  // items [begin, end): element numbers begin+1 .. end
    bool mixed;
    ElementType type;
  };

  [[nodiscard]] const std::vector<ElementBlock>& list(int k) const {
    return k == 0 ? mesh_.cells : k == 1 ? mesh_.facets : mesh_.lower;
  }
  [[nodiscard]] const ElementBlock& block_of(const Item& item) const { return list(item.list)[item.block]; }
  [[nodiscard]] int tag_of(const Item& item) const { return block_of(item).tags[static_cast<std::size_t>(item.local)]; }

  /// Every element, in the order of the ids it came with (file order), else cells, facets,
  /// lower elements in block order.
  void list_elements() {
    bool have_ids = true;
    for (int k = 0; k < 3; ++k)
      for (const ElementBlock& b : list(k)) have_ids = have_ids && (b.empty() || !b.ids.empty());
    std::int64_t position = 0;
    for (int k = 0; k < 3; ++k)
      for (std::size_t b = 0; b < list(k).size(); ++b)
        for (Index e = 0; e < list(k)[b].size(); ++e, ++position)
          items_.push_back({have_ids ? list(k)[b].ids[static_cast<std::size_t>(e)] : position, k, b, e});
    if (have_ids) std::stable_sort(items_.begin(), items_.end(), [](const Item& a, const Item& b) { return a.key < b.key; });
    // Groups interleaved in that order (a generated mesh's facets, face by face) would give a
    // section per run: thousands of sections, which every CGNS reader walks one by one (and the
    // CGNS library writes in quadratic time). Then the elements are grouped by list and group
    // instead, keeping their order within each group; a few runs more than groups keep the
    // file order.
    const auto key = [&](const Item& item) { return std::pair(item.list, tag_of(item)); };
    std::vector<std::pair<int, int>> run_keys;
    for (std::size_t k = 0; k < items_.size(); ++k)
      if (k == 0 || key(items_[k]) != key(items_[k - 1])) run_keys.push_back(key(items_[k]));
    const std::size_t runs = run_keys.size();
    std::sort(run_keys.begin(), run_keys.end());
    const auto distinct = static_cast<std::size_t>(std::unique(run_keys.begin(), run_keys.end()) - run_keys.begin());
    if (runs > distinct + max_extra_sections)
      std::stable_sort(items_.begin(), items_.end(), [&](const Item& a, const Item& b) { return key(a) < key(b); });
  }
  static constexpr std::size_t max_extra_sections = 64;

  [[nodiscard]] std::string group_name(int dim, int tag) const {
    for (const PhysicalGroup& g : mesh_.groups)
      if (g.dim == dim && g.tag == tag) return g.name;
    return "tag_" + std::to_string(tag);
  }

  [[nodiscard]] std::string unique_section_name(std::string name) {
    if (std::find(used_names_.begin(), used_names_.end(), name) != used_names_.end()) {
      const std::string stem = name.substr(0, 28);
      for (int k = 2;; ++k) {
        name = stem + "_" + std::to_string(k);
        if (std::find(used_names_.begin(), used_names_.end(), name) == used_names_.end()) break;
      }
    }
    used_names_.push_back(name);
    return name;
  }

  /// Runs of one dimension and tag become sections: one per type, or one MIXED section when
  /// the types alternate within the run. Facet groups become BCs.
  void plan_sections() {
    for (std::size_t begin = 0; begin < items_.size();) {
      const Item& first = items_[begin];
      const int dim = dimension(block_of(first).type), tag = tag_of(first);
      std::size_t end = begin + 1;
      std::size_t chunks = 1;
      std::vector<ElementType> types{block_of(first).type};
      while (end < items_.size() && dimension(block_of(items_[end]).type) == dim && tag_of(items_[end]) == tag) {
        const ElementType t = block_of(items_[end]).type;
        if (t != block_of(items_[end - 1]).type) {
          ++chunks;
          if (std::find(types.begin(), types.end(), t) == types.end()) types.push_back(t);
        }
        ++end;
      }
      std::string group = tag == 0 ? std::string() : group_name(dim, tag);
      if (!group.empty()) check_cgns_name(group, "group");
      if (chunks > types.size()) {
        sections_.push_back({unique_section_name(group.empty() ? "MIXED" : group), begin, end, true, first_type(begin)});
      } else {
        for (std::size_t k = begin; k < end;) {
          std::size_t stop = k + 1;
          while (stop < end && block_of(items_[stop]).type == block_of(items_[k]).type) ++stop;
          const ElementType t = block_of(items_[k]).type;
          sections_.push_back({unique_section_name(group.empty() ? cgns_type_name(cgns_type(t)) : group), k, stop, false, t});
          k = stop;
        }
      }
      if (dim == Dim - 1 && tag != 0) {
        std::vector<cgsize_t>& numbers = boco(group);
        for (std::size_t k = begin; k < end; ++k) numbers.push_back(static_cast<cgsize_t>(k + 1));
      }
      begin = end;
    }
  }
  [[nodiscard]] ElementType first_type(std::size_t k) const { return block_of(items_[k]).type; }

  std::vector<cgsize_t>& boco(const std::string& name) {
    for (auto& [n, numbers] : bocos_)
      if (n == name) return numbers;
    bocos_.emplace_back(name, std::vector<cgsize_t>{});
    return bocos_.back().second;
  }

  const Mesh<Dim>& mesh_;
  std::vector<Item> items_;
  std::vector<SectionPlan> sections_;
  std::vector<std::string> used_names_;
  std::vector<std::pair<std::string, std::vector<cgsize_t>>> bocos_;
};

}  // namespace detail

#endif  // MESHMOTION_HAVE_CGNS

/// Writes `mesh` as a .cgns file (HDF5 storage), through a temporary file and a rename. Throws
/// InputError for an invalid mesh or a group name CGNS cannot hold (nothing is written),
/// IoError when the library fails, InputError when built without CGNS.
template <int Dim>
void write_cgns(const std::filesystem::path& file, const Mesh<Dim>& mesh) {
#ifdef MESHMOTION_HAVE_CGNS
  detail::CgnsWriter<Dim> writer(mesh);
  detail::write_through_temporary(file, [&](const std::filesystem::path& tmp) { writer.write(tmp, file); });
#else
  (void)mesh;
  throw InputError(file.string() + ": writing CGNS needs the CGNS library (meshmotion was built without it: install "
                   "libcgns-dev and reconfigure)");
#endif
}

/// Writes the CGNS file `source` again as `file` with every zone's coordinates replaced by the
/// mesh's, whose nodes are numbered as read_cgns(source) numbers them (the mesh is the file's,
/// moved): structured zones stay the same blocks, and the sections, BCs, families, block
/// connectivity and solutions are the source's. Through a temporary file and a rename. Throws
/// InputError when the mesh's dimension or node count is not the file's, or a coordinate is
/// not finite (nothing is written); IoError when the library fails.
template <int Dim>
void write_cgns_coordinates(const std::filesystem::path& source, const std::filesystem::path& file, const Mesh<Dim>& mesh) {
#ifdef MESHMOTION_HAVE_CGNS
  detail::CgnsReader reader(source);
  const detail::RawMesh raw = reader.read();
  if (raw.dim != Dim || raw.num_nodes() != mesh.num_nodes())
    throw InputError("write_cgns_coordinates: " + source.string() + " holds a " + std::to_string(raw.dim) + "D mesh of " +
                     std::to_string(raw.num_nodes()) + " nodes (the mesh given is " + std::to_string(Dim) + "D with " +
                     std::to_string(mesh.num_nodes()) + ")");
  if (!mesh.points.allFinite()) throw InputError("write_cgns_coordinates: a coordinate of the mesh is not finite");
  detail::write_through_temporary(file, [&](const std::filesystem::path& tmp) {
    std::filesystem::copy_file(source, tmp, std::filesystem::copy_options::overwrite_existing);
    detail::CgnsFile cgns(tmp, CG_MODE_MODIFY, file);
    static constexpr const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    const std::vector<std::vector<Index>>& zones = reader.zone_nodes();
    for (std::size_t z = 0; z < zones.size(); ++z) {
      std::vector<double> column(zones[z].size());
      for (int d = 0; d < Dim; ++d) {
        for (std::size_t v = 0; v < column.size(); ++v) column[v] = mesh.points(d, zones[z][v]);
        int index = 0;
        cgns.check(detail::cgns_api().cg_coord_write(cgns.id(), 1, static_cast<int>(z) + 1, CGNS_ENUMV(RealDouble), names[d],
                                                     column.data(), &index),
                   "zone " + std::to_string(z + 1) + "/GridCoordinates/" + names[d]);
      }
    }
    cgns.close();
  });
#else
  (void)source;
  (void)mesh;
  throw InputError(file.string() + ": writing CGNS needs the CGNS library (meshmotion was built without it: install "
                   "libcgns-dev and reconfigure)");
#endif
}

}  // namespace meshmotion
