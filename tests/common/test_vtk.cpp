// VTK output: the frames and the series file ParaView reads.
#include <filesystem>
#include <fstream>
#include <sstream>

#include "catch2_compat.hpp"
#include "common/vtk.hpp"

using namespace fem;

namespace {

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("VTK series: two frames of one tetrahedron", "[vtk]") {
  const auto dir = std::filesystem::temp_directory_path() / "fem_test_vtk";
  std::filesystem::remove_all(dir);
  Eigen::Matrix3Xd X(3, 4);
  X << 0, 1, 0, 0,  //
      0, 0, 1, 0,   //
      0, 0, 0, 1;
  const std::vector<Eigen::Vector4i> tets = {Eigen::Vector4i(0, 1, 2, 3)};
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(X.data(), 12);
  const Eigen::VectorXd v = Eigen::VectorXd::Constant(12, 0.5);
  VtkSeries series(dir.string(), "tet");
  series.write_frame(0.0, X, tets, x, v);
  x[11] += 0.25;  // node 3 moves up
  series.write_frame(0.1, X, tets, x, v);
  CHECK(series.frames() == 2);
  const std::string pvd = read(series.pvd_path());
  CHECK(count(pvd, "<DataSet") == 2);
  CHECK(pvd.find("tet_000001.vtu") != std::string::npos);
  const std::string frame = read(dir / "tet_000001.vtu");
  CHECK(frame.find("NumberOfPoints=\"4\" NumberOfCells=\"1\"") != std::string::npos);
  CHECK(frame.find("Name=\"displacement\"") != std::string::npos);
  CHECK(frame.find("\n0 0 0.25\n") != std::string::npos);  // node 3's displacement
  std::filesystem::remove_all(dir);
}

TEST_CASE("VTK series: an unwritable directory is reported", "[vtk]") {
  CHECK_THROWS_WITH(VtkSeries("/proc/fem_cannot_write_here", "x"),
                    test::contains_text("/proc/fem_cannot_write_here"));
}
