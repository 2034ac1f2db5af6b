// VTK output: the frames and the series file ParaView reads.
#include <filesystem>
#include <fstream>
#include <map>
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
  series.commit();
  const std::string pvd = read(series.pvd_path());
  CHECK(count(pvd, "<DataSet") == 2);
  CHECK(pvd.find("tet_000001.vtu") != std::string::npos);
  const std::string frame = read(dir / "tet_000001.vtu");
  CHECK(frame.find("NumberOfPoints=\"4\" NumberOfCells=\"1\"") != std::string::npos);
  CHECK(frame.find("Name=\"displacement\"") != std::string::npos);
  CHECK(frame.find("\n0 0 0.25\n") != std::string::npos);  // node 3's displacement
  std::filesystem::remove_all(dir);
}

namespace {

// One tetrahedron's series of `frames` frames in `dir`, committed or not.
void write_series(const std::filesystem::path& dir, int frames, double shift, bool commit) {
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Identity(3, 4);
  const std::vector<Eigen::Vector4i> tets = {Eigen::Vector4i(0, 1, 2, 3)};
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(X.data(), 12);
  x.array() += shift;
  VtkSeries series(dir.string(), "tet");
  for (int f = 0; f < frames; ++f) series.write_frame(0.1 * f, X, tets, x, x);
  if (commit) series.commit();
}

std::map<std::string, std::string> folder(const std::filesystem::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    files[entry.path().filename().string()] =
        entry.is_regular_file() ? read(entry.path()) : "(a folder)";
  return files;
}

}  // namespace

TEST_CASE("VTK series: a run that stops part-way leaves the earlier series as it was", "[vtk]") {
  const auto dir = std::filesystem::temp_directory_path() / "fem_test_vtk_rerun";
  std::filesystem::remove_all(dir);
  write_series(dir, 3, 0.0, true);
  const auto before = folder(dir);
  CHECK(before.size() == 4);         // three frames and the .pvd
  write_series(dir, 2, 0.5, false);  // destroyed without commit: a run that failed
  CHECK(folder(dir) == before);
  write_series(dir, 2, 0.5, true);  // a whole run: its two frames, the third removed
  const auto after = folder(dir);
  CHECK(after.size() == 3);
  CHECK(after.count("tet_000002.vtu") == 0);
  CHECK(after.at("tet_000001.vtu") != before.at("tet_000001.vtu"));
  CHECK(count(after.at("tet.pvd"), "<DataSet") == 2);
  std::filesystem::remove_all(dir);
}

TEST_CASE("VTK series: an unwritable directory is reported", "[vtk]") {
  CHECK_THROWS_WITH(VtkSeries("/proc/fem_cannot_write_here", "x"),
                    test::contains_text("/proc/fem_cannot_write_here"));
}
