// VTK output: one .vtu (unstructured grid of tetrahedra) per frame and a .pvd series
// that ParaView opens as a time series.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace fem {

class VtkSeries {
 public:
  // Frames go to directory/name_000000.vtu, ...; the series to directory/name.pvd.
  // Creates the directory; throws std::runtime_error naming the path if it cannot. An earlier
  // series of the same name there is replaced: its frames are removed (counted in
  // replaced_frames()), so the folder never mixes two runs' frames. Other files stay.
  VtkSeries(std::string directory, std::string name);

  // Throws std::runtime_error, as the constructor would, when the directory cannot be made or
  // written, and creates nothing: a program checks its output folder before its work and
  // makes it after the work's inputs are known good, so a bad argument leaves no empty folder.
  static void check_writable(const std::string& directory);

  // Writes one frame (x, v stacked: node i at 3i..3i+2) with point data "displacement"
  // (x - rest) and "velocity", and rewrites the .pvd so it is valid if the run stops.
  void write_frame(double time, const Eigen::Matrix3Xd& rest,
                   const std::vector<Eigen::Vector4i>& tets, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& v);

  int frames() const { return static_cast<int>(times_.size()); }
  std::string pvd_path() const;
  int replaced_frames() const { return replaced_frames_; }

 private:
  std::string directory_, name_;
  std::vector<double> times_;
  int replaced_frames_ = 0;
};

}  // namespace fem
