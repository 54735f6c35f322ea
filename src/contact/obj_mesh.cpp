// Reading a mesh solid from a Wavefront OBJ file (docs/contact.md, "Solids and their motion"). Kept
// free of CGAL and of the rest of the contact module: the scene loader's fuzz targets compile this
// file alone.

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cosserat/contact/geometry.hpp"

namespace cosserat {

namespace {

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t end = i;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t' && line[end] != '\r') ++end;
    if (end > i) out.push_back(line.substr(i, end - i));
    i = end;
  }
  return out;
}

struct Face {
  std::array<int, 3> vertices;
  int line;
};

// An undirected edge's two uses, for the closed and orientation checks.
struct EdgeUse {
  int count = 0;
  int forward = 0;  // traversed from the lower to the higher index
  int first_line = 0;
  int second_line = 0;
};

// Signed volume of the closed surface (divergence theorem over the triangles), to find a mesh
// whose faces are consistently clockwise.
double signed_volume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (const auto& [a, b, c] : mesh.triangles) {
    volume += dot(mesh.vertices[a], cross(mesh.vertices[b], mesh.vertices[c]));
  }
  return volume / 6.0;
}

}  // namespace

TriangleMesh read_obj(const std::string& path) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    throw std::runtime_error(fmt::format("{}: cannot read (a directory)", path));
  }
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open ({})", path, std::strerror(errno)));
  TriangleMesh mesh;
  std::vector<Face> faces;
  std::string text;
  int line_number = 0;
  const auto fail = [&](const std::string& what) {
    throw std::runtime_error(fmt::format("{}:{}: {}", path, line_number, what));
  };
  while (std::getline(in, text)) {
    ++line_number;
    const std::vector<std::string_view> word = words(std::string_view(text).substr(0, text.find('#')));
    if (word.empty()) continue;
    if (word[0] == "v") {
      if (word.size() < 4 || word.size() > 5) fail("a vertex needs three coordinates (x y z [w])");
      std::array<double, 3> x{};
      for (int i = 0; i < 3; ++i) {
        const std::string_view token = word[1 + i];
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), x[i]);
        if (error != std::errc() || end != token.data() + token.size() || !std::isfinite(x[i])) {
          fail(fmt::format("vertex coordinate '{}' is not a finite number", token));
        }
      }
      mesh.vertices.push_back({x[0], x[1], x[2]});
    } else if (word[0] == "f") {
      if (word.size() != 4) {
        fail(fmt::format("a face with {} vertices; only triangles are read", word.size() - 1));
      }
      Face face{{}, line_number};
      for (int i = 0; i < 3; ++i) {
        // v, v/vt, v//vn or v/vt/vn: only the position index matters here.
        const std::string_view token = word[1 + i].substr(0, word[1 + i].find('/'));
        long index = 0;
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), index);
        if (error != std::errc() || end != token.data() + token.size() || index == 0) {
          fail(fmt::format("face index '{}' is not a non-zero integer", word[1 + i]));
        }
        // A negative index counts back from the last vertex read so far.
        const long count = static_cast<long>(mesh.vertices.size());
        const long resolved = index < 0 ? count + index : index - 1;
        if (resolved < 0 || (index < 0 && resolved >= count)) {
          fail(fmt::format("face index {} is out of range ({} vertices so far)", index, count));
        }
        if (resolved > 0x7fffffffL) fail(fmt::format("face index {} is out of range", index));
        face.vertices[i] = static_cast<int>(resolved);
      }
      if (face.vertices[0] == face.vertices[1] || face.vertices[1] == face.vertices[2] ||
          face.vertices[2] == face.vertices[0]) {
        fail("a face repeats a vertex");
      }
      faces.push_back(face);
    }
  }
  if (in.bad()) throw std::runtime_error(fmt::format("{}: unreadable", path));
  if (faces.empty()) throw std::runtime_error(fmt::format("{}: no faces", path));
  // Positive indices may point forward in the file, so they are checked once all are read.
  for (const Face& face : faces) {
    for (const int v : face.vertices) {
      if (v >= static_cast<int>(mesh.vertices.size())) {
        throw std::runtime_error(fmt::format("{}:{}: face index {} is out of range ({} vertices)",
                                             path, face.line, v + 1, mesh.vertices.size()));
      }
    }
  }

  std::map<std::pair<int, int>, EdgeUse> edges;
  for (const Face& face : faces) {
    for (int i = 0; i < 3; ++i) {
      const int from = face.vertices[i];
      const int to = face.vertices[(i + 1) % 3];
      EdgeUse& use = edges[std::minmax(from, to)];
      ++use.count;
      if (from < to) ++use.forward;
      (use.count == 1 ? use.first_line : use.second_line) = face.line;
    }
  }
  // Reported in face order, so the message names the first offending edge of the file.
  for (const Face& face : faces) {
    for (int i = 0; i < 3; ++i) {
      const auto [low, high] = std::minmax(face.vertices[i], face.vertices[(i + 1) % 3]);
      const EdgeUse& use = edges[{low, high}];
      if (use.count != 2) {
        throw std::runtime_error(fmt::format(
            "{}: not closed: the edge between vertices {} and {} (face on line {}) is shared by "
            "{} face{}, not two",
            path, low + 1, high + 1, face.line, use.count, use.count == 1 ? "" : "s"));
      }
    }
  }
  for (const Face& face : faces) {
    for (int i = 0; i < 3; ++i) {
      const auto [low, high] = std::minmax(face.vertices[i], face.vertices[(i + 1) % 3]);
      const EdgeUse& use = edges[{low, high}];
      if (use.forward != 1) {
        throw std::runtime_error(fmt::format(
            "{}: inconsistent orientation: the faces on lines {} and {} both run the edge "
            "between vertices {} and {} the same way",
            path, use.first_line, use.second_line, low + 1, high + 1));
      }
    }
  }

  for (const Face& face : faces) mesh.triangles.push_back(face.vertices);
  // Consistent but clockwise seen from outside (inward normals) is the same solid.
  if (signed_volume(mesh) < 0.0) {
    for (auto& triangle : mesh.triangles) std::swap(triangle[1], triangle[2]);
  }
  return mesh;
}

}  // namespace cosserat
