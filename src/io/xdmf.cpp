#include "cosserat/io/xdmf.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

namespace cosserat {
namespace {

std::string xml_escaped(const std::string& text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

constexpr std::string_view kHead = R"(<?xml version="1.0" ?>
<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>
<Xdmf Version="3.0">
  <Domain>
    <Grid Name="cloth" GridType="Collection" CollectionType="Temporal">
)";

constexpr std::string_view kTail = R"(    </Grid>
  </Domain>
</Xdmf>
)";

// One frame is a structured surface whose points are the slab [frame, 0:m, 0:n, 0:3] of
// /positions. The slab is written in XDMF 3's own form, "file:/dataset|start:stride:count:extent"
// inside a plain HDF item, because ParaView's XDMF 3 readers (its default for .xmf) do not read a
// HyperSlab item as geometry: they look up the item's number type before reading it, and a
// HyperSlab has none until read. ParaView's legacy XDMF 2 reader does not know this form.
// The extent is the dataset's when the frame was written, frame + 1 frames: XDMF 3 reads the
// slab from the dataset as it is in the file (the extent only matters when XDMF writes), and a
// frame's text that named the final count would have to be rewritten at every later frame.
//
// A field's values at the grid's nodes in the same form: the slab [frame, 0:m, 0:n] of
// /fields/<name>, or [frame, 0:m, 0:n, 0:3] for a vector.
std::string field_attribute(const std::string& h5_file, int m, int n, std::size_t frame,
                            const XdmfField& field, const std::string& pad) {
  const std::string dimensions =
      field.vector ? fmt::format("{} {} 3", m, n) : fmt::format("{} {}", m, n);
  const std::string slab =
      field.vector ? fmt::format("{} 0 0 0:1 1 1 1:1 {} {} 3:{} {} {} 3", frame, m, n,
                                 frame + 1, m, n)
                   : fmt::format("{} 0 0:1 1 1:1 {} {}:{} {} {}", frame, m, n, frame + 1, m, n);
  return fmt::format(
      R"({pad}  <Attribute Name="{name}" AttributeType="{type}" Center="Node">
{pad}    <DataItem Dimensions="{dimensions}" NumberType="Float" Precision="8"
{pad}              Format="HDF">{file}:/fields/{name}|{slab}</DataItem>
{pad}  </Attribute>
)",
      fmt::arg("pad", pad), fmt::arg("name", xml_escaped(field.name)),
      fmt::arg("type", field.vector ? "Vector" : "Scalar"), fmt::arg("dimensions", dimensions),
      fmt::arg("file", h5_file), fmt::arg("slab", slab));
}

// The cloth's grid of one frame, named `name`, its lines indented by `indent` spaces; `time`
// goes on its own line inside it (empty: the enclosing collection carries the time).
std::string cloth_grid(const std::string& h5_file, int m, int n,
                       const std::vector<XdmfField>& fields, std::size_t frame,
                       const std::string& name, const std::string& time, std::size_t indent) {
  const std::string pad(indent, ' ');
  std::string grid = fmt::format(
      R"({pad}<Grid Name="{name}" GridType="Uniform">
{time}{pad}  <Topology TopologyType="2DSMesh" Dimensions="{m} {n}"/>
{pad}  <Geometry GeometryType="XYZ">
{pad}    <DataItem Dimensions="{m} {n} 3" NumberType="Float" Precision="8"
{pad}              Format="HDF">{file}:/positions|{frame} 0 0 0:1 1 1 1:1 {m} {n} 3:{extent} {m} {n} 3</DataItem>
{pad}  </Geometry>
)",
      fmt::arg("pad", pad), fmt::arg("name", name), fmt::arg("time", time),
      fmt::arg("frame", frame), fmt::arg("extent", frame + 1), fmt::arg("m", m),
      fmt::arg("n", n), fmt::arg("file", h5_file));
  for (const XdmfField& field : fields) grid += field_attribute(h5_file, m, n, frame, field, pad);
  return grid + pad + "</Grid>\n";
}

std::string time_line(double time, std::size_t indent) {
  return fmt::format("{}<Time Value=\"{}\"/>\n", std::string(indent, ' '), time);
}

std::string frame_grid(const std::string& h5_file, int m, int n,
                       const std::vector<XdmfField>& fields, std::size_t frame, double time) {
  return cloth_grid(h5_file, m, n, fields, frame, fmt::format("frame_{}", frame),
                    time_line(time, 8), 6);
}

// With solids, a frame is a spatial collection: the cloth's grid as above (without its own time,
// which the collection carries) and one triangle surface per solid, its vertices the slab
// [frame, 0:nv, 0:3] of /solids/<i>/world_vertices in the same XDMF 3 form.
std::string frame_collection(const std::string& h5_file, int m, int n,
                             const std::vector<XdmfSolid>& solids,
                             const std::vector<XdmfField>& fields, std::size_t frame,
                             double time) {
  std::string grid = fmt::format(
      R"(      <Grid Name="frame_{frame}" GridType="Collection" CollectionType="Spatial">
)",
      fmt::arg("frame", frame));
  grid += time_line(time, 8) + cloth_grid(h5_file, m, n, fields, frame, "cloth", "", 8);
  for (std::size_t i = 0; i < solids.size(); ++i) {
    const XdmfSolid& solid = solids[i];
    grid += fmt::format(
        R"(        <Grid Name="{name}" GridType="Uniform">
          <Topology TopologyType="Triangle" NumberOfElements="{nt}">
            <DataItem Dimensions="{nt} 3" NumberType="Int" Precision="4"
                      Format="HDF">{file}:/solids/{i}/triangles</DataItem>
          </Topology>
          <Geometry GeometryType="XYZ">
            <DataItem Dimensions="{nv} 3" NumberType="Float" Precision="8"
                      Format="HDF">{file}:/solids/{i}/world_vertices|{frame} 0 0:1 1 1:1 {nv} 3:{extent} {nv} 3</DataItem>
          </Geometry>
        </Grid>
)",
        fmt::arg("name", solid.name.empty() ? fmt::format("solid_{}", i) : xml_escaped(solid.name)),
        fmt::arg("i", i), fmt::arg("nt", solid.triangles), fmt::arg("nv", solid.vertices),
        fmt::arg("frame", frame), fmt::arg("extent", frame + 1), fmt::arg("file", h5_file));
  }
  grid += "      </Grid>\n";
  return grid;
}

std::string frame_element(const std::string& h5_file, int m, int n,
                          const std::vector<XdmfSolid>& solids,
                          const std::vector<XdmfField>& fields, std::size_t frame, double time) {
  return solids.empty() ? frame_grid(h5_file, m, n, fields, frame, time)
                        : frame_collection(h5_file, m, n, solids, fields, frame, time);
}

// Writes all of `text` at `offset`; false with errno set if the file took less.
bool write_at(int descriptor, std::string_view text, long offset) {
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t wrote = pwrite(descriptor, text.data() + written, text.size() - written,
                                 static_cast<off_t>(offset) + static_cast<off_t>(written));
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      if (wrote == 0) errno = ENOSPC;
      return false;
    }
    written += static_cast<std::size_t>(wrote);
  }
  return true;
}

}  // namespace

std::string xdmf_document(const std::string& h5_filename_relative, int m, int n,
                          const std::vector<double>& times, const std::vector<XdmfSolid>& solids,
                          const std::vector<XdmfField>& fields) {
  const std::string h5_file = xml_escaped(h5_filename_relative);
  std::string document(kHead);
  for (std::size_t frame = 0; frame < times.size(); ++frame)
    document += frame_element(h5_file, m, n, solids, fields, frame, times[frame]);
  document += kTail;
  return document;
}

XdmfFile::XdmfFile(const std::string& xmf_path, const std::string& h5_filename_relative, int m,
                   int n, const std::vector<double>& times,
                   const std::vector<XdmfSolid>& solids, const std::vector<XdmfField>& fields)
    : path_(xmf_path),
      h5_file_(xml_escaped(h5_filename_relative)),
      m_(m),
      n_(n),
      solids_(solids),
      fields_(fields) {
  // The temporary sits in the same folder so that rename() replaces within one file system,
  // which POSIX makes atomic; the descriptor follows the file to its final name.
  const std::string partial_path = xmf_path + ".partial";
  descriptor_ = open(partial_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (descriptor_ < 0)
    throw std::runtime_error(
        fmt::format("XDMF file '{}': cannot create it: {}", partial_path, std::strerror(errno)));
  const std::string document = xdmf_document(h5_filename_relative, m, n, times, solids, fields);
  if (!write_at(descriptor_, document, 0)) {
    const int error = errno;
    close(descriptor_);
    throw std::runtime_error(
        fmt::format("XDMF file '{}': write failed: {}", partial_path, std::strerror(error)));
  }
  std::error_code error;
  std::filesystem::rename(partial_path, xmf_path, error);
  if (error) {
    close(descriptor_);
    throw std::runtime_error(fmt::format("XDMF file '{}': rename from '{}' failed: {}", xmf_path,
                                         partial_path, error.message()));
  }
  tail_offset_ = static_cast<long>(document.size() - kTail.size());
  frames_ = times.size();
}

XdmfFile::~XdmfFile() { close(descriptor_); }

// A write that extends the file can fail part way (a full disk); the closing tags then go back
// where they were and the file is cut there, which needs no new space.
void XdmfFile::append(double time) {
  const std::string element = frame_element(h5_file_, m_, n_, solids_, fields_, frames_, time);
  if (!write_at(descriptor_, element + std::string(kTail), tail_offset_)) {
    const int error = errno;
    const auto end = static_cast<off_t>(tail_offset_ + static_cast<long>(kTail.size()));
    const bool restored =
        write_at(descriptor_, kTail, tail_offset_) && ftruncate(descriptor_, end) == 0;
    throw std::runtime_error(fmt::format(
        "XDMF file '{}': appending frame {} failed: {}{}", path_, frames_, std::strerror(error),
        restored ? " (the file still describes the earlier frames)" : ""));
  }
  tail_offset_ += static_cast<long>(element.size());
  ++frames_;
}

}  // namespace cosserat
