#include "common/vtk.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/atomic_file.hpp"

namespace fem {
namespace {

std::string frame_file(const std::string& name, int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "_%06d.vtu", frame);
  return name + buf;
}

// One frame: the deformed tetrahedra, with the displacement and the velocity at the nodes.
void write_vtu(std::ostream& out, const Eigen::Matrix3Xd& rest,
               const std::vector<Eigen::Vector4i>& tets, const Eigen::VectorXd& x,
               const Eigen::VectorXd& v) {
  const Eigen::Index n = rest.cols();
  out.precision(9);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << tets.size()
      << "\">\n<Points>\n"
      << "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < n; ++i)
    out << x[3 * i] << ' ' << x[3 * i + 1] << ' ' << x[3 * i + 2] << '\n';
  out << "</DataArray>\n</Points>\n<Cells>\n"
      << "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : tets) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < tets.size(); ++e) out << 4 * (e + 1) << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < tets.size(); ++e) out << "10\n";  // VTK_TETRA
  out << "</DataArray>\n</Cells>\n<PointData Vectors=\"displacement\">\n"
      << "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < n; ++i)
    out << x[3 * i] - rest(0, i) << ' ' << x[3 * i + 1] - rest(1, i) << ' '
        << x[3 * i + 2] - rest(2, i) << '\n';
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"velocity\" "
         "NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < n; ++i)
    out << v[3 * i] << ' ' << v[3 * i + 1] << ' ' << v[3 * i + 2] << '\n';
  out << "</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

// name_NNNNNN.vtu: a frame of the series `name` (not of another series in the same folder).
bool is_frame_of(const std::string& file, const std::string& name) {
  const std::size_t digits = 6, size = name.size() + 1 + digits + 4;
  if (file.size() != size || file.compare(0, name.size() + 1, name + "_") != 0 ||
      file.compare(size - 4, 4, ".vtu") != 0)
    return false;
  return std::all_of(file.begin() + static_cast<long>(name.size()) + 1, file.end() - 4,
                     [](char c) { return c >= '0' && c <= '9'; });
}

// The NNNNNN of a frame of the series `name` (is_frame_of).
long frame_number(const std::string& file, const std::string& name) {
  return std::stol(file.substr(name.size() + 1, file.size() - name.size() - 5));
}

}  // namespace

void VtkSeries::check_writable(const std::string& directory) {
  // Permission bits do not tell (root passes them on a read-only /proc): try for real, and
  // undo what the try made.
  namespace fs = std::filesystem;
  std::error_code error;
  fs::path existing = fs::absolute(directory, error);
  while (!existing.empty() && !fs::exists(existing, error) && existing != existing.parent_path())
    existing = existing.parent_path();
  const fs::path probe = fs::path(directory) / ".fem_write_probe";
  const bool made = fs::create_directories(directory, error);
  bool writable = !error && fs::is_directory(directory, error);
  if (writable) {
    writable = static_cast<bool>(std::ofstream(probe));
    fs::remove(probe, error);
  }
  if (made) {
    for (fs::path p = fs::absolute(directory, error); p != existing && p != p.parent_path();
         p = p.parent_path())
      fs::remove(p, error);
  }
  if (!writable)
    throw std::runtime_error("cannot create or write the output directory '" + directory + "'");
}

VtkSeries::VtkSeries(std::string directory, std::string name)
    : directory_(std::move(directory)), name_(std::move(name)) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error || !fs::is_directory(directory_))
    throw std::runtime_error("cannot create the output directory '" + directory_ +
                             "': " + error.message());
  // A staging folder found here is a run's that stopped without its commit (killed): the
  // caller holds the folder's lock (common/run_lock.hpp), so no live run owns it.
  staging_ = (fs::path(directory_) / ("." + name_ + ".new")).string();
  fs::remove_all(staging_, error);
  if (!fs::create_directory(staging_, error))
    throw std::runtime_error("cannot create the staging folder '" + staging_ +
                             "': " + error.message());
}

VtkSeries::~VtkSeries() {
  std::error_code error;
  if (!committed_ && !kept_) std::filesystem::remove_all(staging_, error);
}

std::string VtkSeries::keep_staged() {
  kept_ = true;
  return staging_path(name_ + ".pvd");
}

std::string VtkSeries::staging_path(const std::string& file) const {
  return (std::filesystem::path(staging_) / file).string();
}

std::string VtkSeries::pvd_path() const {
  return (std::filesystem::path(directory_) / (name_ + ".pvd")).string();
}

void VtkSeries::write_frame(double time, const Eigen::Matrix3Xd& rest,
                            const std::vector<Eigen::Vector4i>& tets, const Eigen::VectorXd& x,
                            const Eigen::VectorXd& v) {
  write_file_atomically(staging_path(frame_file(name_, frames())),
                        [&](std::ostream& out) { write_vtu(out, rest, tets, x, v); });
  times_.push_back(time);
  write_file_atomically(staging_path(name_ + ".pvd"), [&](std::ostream& pvd) {
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n"
        << "<Collection>\n";
    for (int f = 0; f < frames(); ++f)
      pvd << "<DataSet timestep=\"" << times_[f] << "\" part=\"0\" file=\"" << frame_file(name_, f)
          << "\"/>\n";
    pvd << "</Collection>\n</VTKFile>\n";
  });
}

void VtkSeries::commit() {
  namespace fs = std::filesystem;
  if (committed_ || frames() == 0) return;
  std::vector<fs::path> earlier;
  for (const auto& entry : fs::directory_iterator(directory_))
    if (is_frame_of(entry.path().filename().string(), name_)) earlier.push_back(entry.path());
  replaced_frames_ = static_cast<int>(earlier.size());
  const auto move = [&](const std::string& file) {
    std::error_code error;
    fs::rename(staging_path(file), fs::path(directory_) / file, error);
    if (error)
      throw std::runtime_error("cannot move '" + staging_path(file) + "' into '" + directory_ +
                               "': " + error.message());
  };
  for (int f = 0; f < frames(); ++f) move(frame_file(name_, f));
  move(name_ + ".pvd");
  committed_ = true;
  std::error_code error;
  for (const fs::path& frame : earlier)
    if (frame_number(frame.filename().string(), name_) >= frames()) fs::remove(frame, error);
  fs::remove_all(staging_, error);
}

}  // namespace fem
