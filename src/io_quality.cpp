// Reading, writing and quality reports of the compiled library, 2D and 3D.

#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/io/openfoam.hpp"
#include "meshmotion/io/openfoam_reader.hpp"
#include "meshmotion/quality/cell_quality.hpp"
#include "meshmotion/quality/quality_report.hpp"

namespace meshmotion {

template AnyMesh detail::read_any_mesh<0>(const std::filesystem::path&, const ReadOptions&);
template PolyMesh detail::read_polymesh_of<0>(const std::filesystem::path&);
template void detail::write_moved_case_of<0>(const std::filesystem::path&, const std::filesystem::path&, const Mesh<3>&);
template Mesh<2> read_mesh_as<2>(const std::filesystem::path&, const ReadOptions&);
template Mesh<3> read_mesh_as<3>(const std::filesystem::path&, const ReadOptions&);
template void write_mesh<2>(const std::filesystem::path&, const Mesh<2>&, const WriteOptions&);
template void write_mesh<3>(const std::filesystem::path&, const Mesh<3>&, const WriteOptions&);
template std::vector<CellQuality> evaluate_cells<2>(const Mesh<2>&, Metric, const QualityOptions&);
template std::vector<CellQuality> evaluate_cells<3>(const Mesh<3>&, Metric, const QualityOptions&);
template QualityReport make_report<2>(const Mesh<2>&, Metric, const std::vector<CellQuality>&, const ReportOptions&);
template QualityReport make_report<3>(const Mesh<3>&, Metric, const std::vector<CellQuality>&, const ReportOptions&);
template QualityReport quality_report<2>(const Mesh<2>&, Metric, const ReportOptions&);
template QualityReport quality_report<3>(const Mesh<3>&, Metric, const ReportOptions&);

}  // namespace meshmotion
