// VTK output: one .vtu (unstructured grid of tetrahedra) per frame and a .pvd series
// that ParaView opens as a time series.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace fem {

class VtkSeries {
 public:
  // Frames go to directory/name_000000.vtu, ...; the series to directory/name.pvd. Creates
  // the directory; throws std::runtime_error naming the path if it cannot.
  //
  // A run that fails part-way (a solve that diverges, a full disk) must not cost the user the
  // earlier complete series of the same name there: the frames and the .pvd are written into
  // a hidden staging folder beside them (directory/.name.new, whose .pvd is valid after every
  // frame) and take the series' names only in commit(). A series destroyed without commit()
  // removes its staging folder and leaves the directory as it was. Other files stay.
  VtkSeries(std::string directory, std::string name);
  ~VtkSeries();
  VtkSeries(const VtkSeries&) = delete;
  VtkSeries& operator=(const VtkSeries&) = delete;

  // Throws std::runtime_error, as the constructor would, when the directory cannot be made or
  // written, and creates nothing: a program checks its output folder before its work and
  // makes it after the work's inputs are known good, so a bad argument leaves no empty folder.
  static void check_writable(const std::string& directory);

  // Writes one frame (x, v stacked: node i at 3i..3i+2) with point data "displacement"
  // (x - rest) and "velocity", and rewrites the .pvd so it is valid if the run stops.
  void write_frame(double time, const Eigen::Matrix3Xd& rest,
                   const std::vector<Eigen::Vector4i>& tets, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& v);

  // The new series takes the place of the earlier one: each frame renamed over the frame of
  // its number, then the .pvd, then the earlier frames beyond the new count removed (counted
  // in replaced_frames()). Renames need no space, so a full disk cannot stop it half-way.
  void commit();

  // A run stopped on purpose (Ctrl-C) keeps what it wrote where it is, the earlier series
  // untouched: the staging folder stays (the next run into the directory removes it). Returns
  // the .pvd of the frames written so far.
  std::string keep_staged();

  int frames() const { return static_cast<int>(times_.size()); }
  // The series' .pvd in the directory (it names the new frames once commit() has run).
  std::string pvd_path() const;
  int replaced_frames() const { return replaced_frames_; }

 private:
  std::string staging_path(const std::string& file) const;

  std::string directory_, name_, staging_;
  std::vector<double> times_;
  int replaced_frames_ = 0;
  bool committed_ = false, kept_ = false;
};

}  // namespace fem
