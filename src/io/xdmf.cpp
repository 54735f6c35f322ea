#include "cosserat/io/xdmf.hpp"

#include <cstddef>
#include <filesystem>
#include <fstream>
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

// One frame is a structured surface whose points are the slab [frame, 0:m, 0:n, 0:3] of
// /positions. The slab is written in XDMF 3's own form, "file:/dataset|start:stride:count:extent"
// inside a plain HDF item, because ParaView's XDMF 3 readers (its default for .xmf) do not read a
// HyperSlab item as geometry: they look up the item's number type before reading it, and a
// HyperSlab has none until read. ParaView's legacy XDMF 2 reader does not know this form.
std::string frame_grid(const std::string& h5_file, int m, int n, std::size_t frame,
                       std::size_t frames, double time) {
  return fmt::format(
      R"(      <Grid Name="frame_{frame}" GridType="Uniform">
        <Time Value="{time}"/>
        <Topology TopologyType="2DSMesh" Dimensions="{m} {n}"/>
        <Geometry GeometryType="XYZ">
          <DataItem Dimensions="{m} {n} 3" NumberType="Float" Precision="8"
                    Format="HDF">{file}:/positions|{frame} 0 0 0:1 1 1 1:1 {m} {n} 3:{frames} {m} {n} 3</DataItem>
        </Geometry>
      </Grid>
)",
      fmt::arg("frame", frame), fmt::arg("frames", frames), fmt::arg("time", time),
      fmt::arg("m", m), fmt::arg("n", n), fmt::arg("file", h5_file));
}

std::string xdmf_document(const std::string& h5_filename_relative, int m, int n,
                          const std::vector<double>& times) {
  const std::string h5_file = xml_escaped(h5_filename_relative);
  std::string document = R"(<?xml version="1.0" ?>
<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>
<Xdmf Version="3.0">
  <Domain>
    <Grid Name="cloth" GridType="Collection" CollectionType="Temporal">
)";
  for (std::size_t frame = 0; frame < times.size(); ++frame) {
    document += frame_grid(h5_file, m, n, frame, times.size(), times[frame]);
  }
  document += R"(    </Grid>
  </Domain>
</Xdmf>
)";
  return document;
}

}  // namespace

void write_xdmf(const std::string& xmf_path, const std::string& h5_filename_relative, int m, int n,
                const std::vector<double>& times) {
  // The temporary sits in the same folder so that rename() replaces within one file system,
  // which POSIX makes atomic.
  const std::string partial_path = xmf_path + ".partial";
  {
    std::ofstream out(partial_path, std::ios::binary | std::ios::trunc);
    out << xdmf_document(h5_filename_relative, m, n, times);
    out.close();
    if (!out) throw std::runtime_error(fmt::format("XDMF file '{}': write failed", partial_path));
  }
  std::error_code error;
  std::filesystem::rename(partial_path, xmf_path, error);
  if (error) {
    throw std::runtime_error(fmt::format("XDMF file '{}': rename from '{}' failed: {}", xmf_path,
                                         partial_path, error.message()));
  }
}

}  // namespace cosserat
