#pragma once
// The XDMF 3 description of /positions that lets ParaView open the HDF5 output as a time series
// of structured surfaces (with its "Xdmf3 Reader S" or "T", the default for .xmf), coloured by
// the fields of /fields, and with it the rigid solids of /solids as triangle surfaces moving
// with it.

#include <cstddef>
#include <string>
#include <vector>

namespace cosserat {

// A rigid solid as the XDMF file shows it: a surface of `triangles` triangles
// (/solids/<i>/triangles) whose `vertices` vertices at frame f are /solids/<i>/world_vertices[f],
// i the solid's index in the list.
struct XdmfSolid {
  std::string name;
  long vertices = 0;
  long triangles = 0;
};

// A per-node field of the cloth, /fields/<name> ([frames, m, n], or [frames, m, n, 3] for a
// vector), shown as a node attribute of every frame's grid so that ParaView colours by it.
struct XdmfField {
  std::string name;
  bool vector = false;
};

// The whole XDMF text describing frames 0 .. times.size() - 1 of /positions, an array
// [frames, m, n, 3] in h5_filename_relative (a path relative to the folder of the XDMF file),
// and of each of `fields`. Frame f's element does not depend on how many frames follow it, so
// that a growing series adds one element per frame and rewrites nothing before it. Without
// solids a frame is the cloth's grid; with solids, a spatial collection of the cloth and each
// solid.
std::string xdmf_document(const std::string& h5_filename_relative, int m, int n,
                          const std::vector<double>& times,
                          const std::vector<XdmfSolid>& solids = {},
                          const std::vector<XdmfField>& fields = {});

// The XDMF file of a run's output, growing by one frame at a time (docs/output.md). Every
// failure throws std::runtime_error naming the file. Not collective: one rank owns it.
class XdmfFile {
 public:
  // Writes xmf_path describing the frames at `times` (those already in the HDF5 file): beside
  // its final name first, then renamed over it, so a reader sees the previous file or the new
  // one, never a partial one. The file stays open for append().
  XdmfFile(const std::string& xmf_path, const std::string& h5_filename_relative, int m, int n,
           const std::vector<double>& times, const std::vector<XdmfSolid>& solids = {},
           const std::vector<XdmfField>& fields = {});
  ~XdmfFile();
  XdmfFile(const XdmfFile&) = delete;
  XdmfFile& operator=(const XdmfFile&) = delete;

  // Adds the next frame, at simulated `time`: one write of its element and the closing tags
  // over the old closing tags, whatever the number of frames before it. If that write fails
  // the closing tags are put back, so the file still describes the earlier frames.
  void append(double time);

  std::size_t frames() const { return frames_; }

 private:
  std::string path_;
  std::string h5_file_;  // escaped for XML
  int m_, n_;
  std::vector<XdmfSolid> solids_;
  std::vector<XdmfField> fields_;
  int descriptor_ = -1;
  long tail_offset_ = 0;  // where the closing tags start: the next frame's element goes there
  std::size_t frames_ = 0;
};

}  // namespace cosserat
