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
  // Creates the directory; throws std::runtime_error naming the path if it cannot.
  VtkSeries(std::string directory, std::string name);

  // Writes one frame (x, v stacked: node i at 3i..3i+2) with point data "displacement"
  // (x - rest) and "velocity", and rewrites the .pvd so it is valid if the run stops.
  void write_frame(double time, const Eigen::Matrix3Xd& rest,
                   const std::vector<Eigen::Vector4i>& tets, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& v);

  int frames() const { return static_cast<int>(times_.size()); }
  std::string pvd_path() const;

 private:
  std::string directory_, name_;
  std::vector<double> times_;
};

}  // namespace fem
