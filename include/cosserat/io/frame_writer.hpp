#pragma once
// The HDF5 output of a run (docs/output.md, "HDF5"): one frame of positions per
// write_frame, written collectively by every rank as its block's hyperslab (parallel HDF5),
// appended and flushed at once, and named in the XDMF file beside it by rank 0 (one element
// appended per frame, xdmf.hpp), so that a killed run leaves both files readable with every
// frame written so far. The rigid solids of a contact scene (`/solids`, same section) are written
// beside the cloth, from plain data (SolidOutline, Pose), by rank 0; per-node fields (NodeField)
// like the positions, each rank its block.

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "cosserat/contact/geometry.hpp"
#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat {

namespace hdf5 {
class File;
}
class XdmfFile;
struct XdmfSolid;
struct XdmfField;

// What the output needs of a rigid solid: its name and its surface in its own frame (a plane's
// as a square, SolidGeometry::surface). The same on every rank.
struct SolidOutline {
  std::string name;
  TriangleMesh surface;
};

// A per-node field written beside the positions (docs/output.md, "Fields"): /fields/<name>,
// [frames, m, n] or, for a vector, [frames, m, n, 3], with its units as the dataset's `units`
// attribute; a node attribute of every frame in the XDMF file.
struct NodeField {
  std::string name;
  std::string units;
  bool vector = false;
};

// One frame of a NodeField at the block's owned nodes: a scalar field, or a vector one.
using NodeFieldValues = std::variant<const Field<double>*, const Field<Vec3>*>;

// The XDMF file written beside the HDF5 file `h5_path`: the same name with .xmf.
std::string xdmf_path(const std::string& h5_path);

// Every failure throws std::runtime_error naming the file and the operation that failed. Every
// member is collective over the block's communicator.
class FrameWriter {
 public:
  // Creates h5_path (truncating an existing file) for the block's m x n grid and records the
  // scene text as read, the integrator name, the build version and the --set strings as root
  // attributes. Each of `solids` gets its group /solids/<i> (docs/output.md); without solids
  // the file holds no /solids. Each of `fields` gets its dataset /fields/<name>; without
  // fields the file holds no /fields. Throws std::invalid_argument for a solid without
  // triangles or with a triangle's vertex index out of range, or for two fields of one name.
  FrameWriter(const std::string& h5_path, const Block& block, const std::string& scene_text,
              const std::string& integrator, const std::string& version,
              const std::vector<std::string>& overrides,
              const std::vector<SolidOutline>& solids = {},
              const std::vector<NodeField>& fields = {});

  // Reopens the output of an earlier run to continue it after a restart from `step`: the
  // frames up to that step are kept, later ones (written after the checkpoint) dropped. The file
  // must be that run's: written for `scene_text` on this grid, holding every frame up to
  // `last_scheduled_frame`, the last one the schedule put at or before `step` (with adaptive
  // steps, whose frames are scheduled in time, up to `last_scheduled_time` instead), and
  // holding exactly `solids` (names and surfaces) and `fields` (names, shapes and units) with
  // their frames; else it throws before changing anything. The solids' and fields' frames are
  // cut with the cloth's.
  FrameWriter(const std::string& h5_path, const Block& block, long step,
              const std::string& scene_text, long last_scheduled_frame,
              double last_scheduled_time = 0.0, const std::vector<SolidOutline>& solids = {},
              const std::vector<NodeField>& fields = {});

  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Appends the owned nodes of `positions` as one frame [k][l][xyz] of /positions. The frame
  // is on disk and named in the XDMF file when this returns. `solid_poses` places the solids
  // given at construction, one pose each in their order (the same on every rank), and
  // `field_values` gives the fields given at construction, one each in their order, a vector
  // field's as a Field<Vec3>; throws std::invalid_argument, before writing, when a count or a
  // field's kind differs.
  void write_frame(long step, double time, const Field<Vec3>& positions,
                   const std::vector<Pose>& solid_poses = {},
                   const std::vector<NodeFieldValues>& field_values = {});

  // Writes or replaces a root string attribute, e.g. the final `status`.
  void set_attribute(const std::string& name, const std::string& value);

  long frames() const { return static_cast<long>(steps_.size()); }
  long last_step() const { return steps_.empty() ? -1 : steps_.back(); }

 private:
  struct Datasets;
  std::string h5_filename() const;
  std::vector<XdmfSolid> xdmf_solids() const;
  std::vector<XdmfField> xdmf_fields() const;

  const Block* block_;
  std::unique_ptr<hdf5::File> file_;
  std::unique_ptr<Datasets> datasets_;
  std::unique_ptr<XdmfFile> xdmf_;  // rank 0's; created with the first frame
  std::string h5_path_;
  std::string xmf_path_;
  int rank_ = 0;
  std::vector<SolidOutline> solids_;
  std::vector<NodeField> fields_;
  std::vector<double> times_;
  std::vector<long> steps_;
};

}  // namespace cosserat
