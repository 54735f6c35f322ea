#pragma once
// The HDF5 output of a run (shared/spec/SCENE_FORMAT.md, "Output"): one frame of positions per
// write_frame, appended and flushed at once, with the XDMF file beside it rewritten each time,
// so that a killed run leaves both files readable with every frame written so far.

#include <memory>
#include <string>
#include <vector>

namespace cosserat {

// Every failure throws std::runtime_error naming the file and the operation that failed.
class FrameWriter {
 public:
  // Creates h5_path (truncating an existing file) for an m x n grid and records the scene text
  // as read, the integrator name, the build version and the --set strings as root attributes.
  FrameWriter(const std::string& h5_path, int m, int n, const std::string& scene_text,
              const std::string& integrator, const std::string& version,
              const std::vector<std::string>& overrides);
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // positions holds m * n * 3 doubles laid out [k][l][xyz], l fastest: the C order of one
  // frame of /positions. The frame is on disk and named in the XDMF file when this returns.
  void write_frame(long step, double time, const double* positions);

  // Writes or replaces a root string attribute, e.g. the final `status`.
  void set_attribute(const std::string& name, const std::string& value);

  long frames() const;

 private:
  // HDF5 handles stay in the .cpp so that hdf5.h is not pulled into every driver.
  struct Hdf5Output;
  std::unique_ptr<Hdf5Output> output_;
  std::string h5_path_;
  std::string xmf_path_;
  int m_;
  int n_;
  std::vector<double> times_;
};

}  // namespace cosserat
