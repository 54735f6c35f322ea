#include "cosserat/io/frame_writer.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <variant>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cosserat/io/xdmf.hpp"
#include "hdf5_file.hpp"

namespace cosserat {

using hdf5::Handle;

namespace {

// HDF5 refuses chunks of 4 GiB or more. One frame is one chunk, so that appending a frame
// touches one chunk, unless the frame is that large; then it is split into bands of rows k
// (and of columns l only if a single row is too large). `components` values per node (3 for
// the positions), or one value and no last dimension when it is 0.
std::vector<hsize_t> node_chunk(int m, int n, hsize_t components) {
  constexpr hsize_t max_chunk_bytes = (hsize_t{1} << 32) - 1;
  const hsize_t max_nodes = max_chunk_bytes / (std::max<hsize_t>(components, 1) * sizeof(double));
  const hsize_t columns = std::min<hsize_t>(static_cast<hsize_t>(n), max_nodes);
  const hsize_t rows = std::min<hsize_t>(static_cast<hsize_t>(m), max_nodes / columns);
  std::vector<hsize_t> chunk{1, rows, columns};
  if (components > 0) chunk.push_back(components);
  return chunk;
}

// Long runs write thousands of frames; a chunk of this many times or steps keeps the index of
// the one-dimensional datasets small.
constexpr std::array<hsize_t, 1> series_chunk{1024};

// The shape of one frame of a node series: [m, n, components], or [m, n] when it is 0.
std::vector<hsize_t> node_shape(int m, int n, hsize_t components) {
  std::vector<hsize_t> shape{static_cast<hsize_t>(m), static_cast<hsize_t>(n)};
  if (components > 0) shape.push_back(components);
  return shape;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string joined;
  for (const std::string& line : lines) {
    if (!joined.empty()) joined += '\n';
    joined += line;
  }
  return joined;
}


// A dataset of frames: the first dimension is unlimited and grows by one per written frame.
Handle create_series(const hdf5::File& file, const char* name, hid_t file_type,
                     std::span<const hsize_t> frame_shape, std::span<const hsize_t> chunk) {
  std::array<hsize_t, 4> dims{0, 0, 0, 0};
  std::array<hsize_t, 4> max_dims{H5S_UNLIMITED, 0, 0, 0};
  std::ranges::copy(frame_shape, dims.begin() + 1);
  std::ranges::copy(frame_shape, max_dims.begin() + 1);
  const int rank = static_cast<int>(frame_shape.size()) + 1;
  const std::string what = fmt::format("create dataset {}", name);

  const Handle space =
      file.open(H5Screate_simple(rank, dims.data(), max_dims.data()), H5Sclose, what);
  const Handle properties = file.open(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, what);
  file.check(H5Pset_chunk(properties.get(), rank, chunk.data()), what + " (chunk shape)");
  // Without modification times, the same run writes the same bytes: outputs compare with cmp.
  file.check(H5Pset_obj_track_times(properties.get(), false), what + " (no time stamps)");
  return file.open(H5Dcreate2(file.get(), name, file_type, space.get(), H5P_DEFAULT,
                              properties.get(), H5P_DEFAULT),
                   H5Dclose, what);
}

// Sets the number of frames of a series; collective.
void resize_series(const hdf5::File& file, const Handle& dataset, hsize_t frames,
                   const std::string& what) {
  const Handle space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  std::array<hsize_t, 4> extent{};
  file.check(H5Sget_simple_extent_dims(space.get(), extent.data(), nullptr), what);
  extent[0] = frames;
  file.check(H5Dset_extent(dataset.get(), extent.data()), what + " (extent)");
}

// Writes `values` as the slab [start, start + count) of a dataset whose every rank holds the
// same data: rank 0 (`writer`) writes, the others take part in the collective call with an
// empty selection.
void write_replicated(const hdf5::File& file, const Handle& dataset,
                      std::span<const hsize_t> start, std::span<const hsize_t> count,
                      hid_t memory_type, const void* values, bool writer,
                      const std::string& what) {
  const Handle file_space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  const Handle memory_space =
      file.open(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr),
                H5Sclose, what);
  if (writer) {
    file.check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                   count.data(), nullptr),
               what + " (select)");
  } else {
    file.check(H5Sselect_none(file_space.get()), what + " (select)");
    file.check(H5Sselect_none(memory_space.get()), what + " (select)");
  }
  file.check(H5Dwrite(dataset.get(), memory_type, memory_space.get(), file_space.get(),
                      file.collective(), values),
             what);
}

// Writes one value of a one-dimensional series at `frame`.
void write_series_value(const hdf5::File& file, const Handle& dataset, hsize_t frame,
                        hid_t memory_type, const void* value, bool writer,
                        const std::string& what) {
  const std::array<hsize_t, 1> at{frame}, one{1};
  write_replicated(file, dataset, at, one, memory_type, value, writer, what);
}

template <class T>
std::vector<T> read_series(const hdf5::File& file, const Handle& dataset, hid_t memory_type,
                           const std::string& what) {
  const Handle space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  hsize_t frames = 0;
  file.check(H5Sget_simple_extent_dims(space.get(), &frames, nullptr), what);
  std::vector<T> values(frames);
  if (frames > 0)
    file.check(H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, file.collective(),
                       values.data()),
               what);
  return values;
}

// --- Rigid solids (docs/output.md, "HDF5"): replicated on every rank, so rank 0 writes their data;
// the creation and extension of their datasets is collective like every other's.

// One solid's frames: its pose and its surface placed by that pose.
struct SolidSeries {
  Handle position;
  Handle orientation;
  Handle world_vertices;
};

std::string solid_group(std::size_t index) { return fmt::format("/solids/{}", index); }

void check_outline(const SolidOutline& solid, std::size_t index) {
  const TriangleMesh& surface = solid.surface;
  if (surface.triangles.empty())
    throw std::invalid_argument(
        fmt::format("solid {} ('{}'): its surface has no triangles to write", index, solid.name));
  const auto vertices = static_cast<long>(surface.vertices.size());
  for (const auto& triangle : surface.triangles)
    for (const int vertex : triangle)
      if (vertex < 0 || vertex >= vertices)
        throw std::invalid_argument(
            fmt::format("solid {} ('{}'): a triangle names vertex {} of {}", index, solid.name,
                        vertex, vertices));
}

std::vector<double> placed_vertices(const Pose& pose, const std::vector<Vec3>& local) {
  std::vector<double> world;
  world.reserve(3 * local.size());
  for (const Vec3& v : local) {
    const Vec3 p = pose.to_world(v);
    world.insert(world.end(), {p.x, p.y, p.z});
  }
  return world;
}

std::vector<double> flattened(const std::vector<Vec3>& points) {
  std::vector<double> values;
  values.reserve(3 * points.size());
  for (const Vec3& p : points) values.insert(values.end(), {p.x, p.y, p.z});
  return values;
}

std::vector<std::int32_t> flattened(const std::vector<std::array<int, 3>>& triangles) {
  std::vector<std::int32_t> values;
  values.reserve(3 * triangles.size());
  for (const auto& t : triangles) values.insert(values.end(), t.begin(), t.end());
  return values;
}

// A group without time stamps, so that the same run writes the same bytes.
void create_group(const hdf5::File& file, const std::string& name) {
  const std::string what = fmt::format("create group {}", name);
  const Handle properties = file.open(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, what);
  file.check(H5Pset_obj_track_times(properties.get(), false), what + " (no time stamps)");
  file.open(H5Gcreate2(file.get(), name.c_str(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
            H5Gclose, what);
}

// A fixed [rows, 3] dataset written whole by rank 0.
void write_table(const hdf5::File& file, const std::string& name, hid_t file_type,
                 hid_t memory_type, hsize_t rows, const void* values, bool writer) {
  const std::string what = fmt::format("write dataset {}", name);
  const std::array<hsize_t, 2> dims{rows, 3};
  const Handle space = file.open(H5Screate_simple(2, dims.data(), nullptr), H5Sclose, what);
  const Handle properties = file.open(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, what);
  file.check(H5Pset_obj_track_times(properties.get(), false), what + " (no time stamps)");
  const Handle dataset =
      file.open(H5Dcreate2(file.get(), name.c_str(), file_type, space.get(), H5P_DEFAULT,
                           properties.get(), H5P_DEFAULT),
                H5Dclose, what);
  const std::array<hsize_t, 2> origin{0, 0};
  write_replicated(file, dataset, origin, dims, memory_type, values, writer, what);
}

SolidSeries create_solid(const hdf5::File& file, std::size_t index, const SolidOutline& solid,
                         bool writer) {
  const std::string group = solid_group(index);
  create_group(file, group);
  {
    const Handle handle = file.open(H5Gopen2(file.get(), group.c_str(), H5P_DEFAULT), H5Gclose,
                                    fmt::format("open group {}", group));
    file.write_attribute(handle.get(), "name", solid.name);
  }
  const std::vector<double> vertices = flattened(solid.surface.vertices);
  const std::vector<std::int32_t> triangles = flattened(solid.surface.triangles);
  const auto nv = static_cast<hsize_t>(solid.surface.vertices.size());
  write_table(file, group + "/vertices", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, nv, vertices.data(),
              writer);
  write_table(file, group + "/triangles", H5T_STD_I32LE, H5T_NATIVE_INT32,
              static_cast<hsize_t>(solid.surface.triangles.size()), triangles.data(), writer);
  // One frame of a surface is one chunk, as for the cloth (under HDF5's 4 GiB chunk limit).
  constexpr hsize_t max_vertices = ((hsize_t{1} << 32) - 1) / (3 * sizeof(double));
  const std::array<hsize_t, 2> surface_shape{nv, 3};
  const std::array<hsize_t, 3> surface_chunk{1, std::min(nv, max_vertices), 3};
  const std::array<hsize_t, 1> three{3}, four{4};
  const std::array<hsize_t, 2> position_chunk{series_chunk[0], 3};
  const std::array<hsize_t, 2> orientation_chunk{series_chunk[0], 4};
  return SolidSeries{
      create_series(file, (group + "/position").c_str(), H5T_IEEE_F64LE, three, position_chunk),
      create_series(file, (group + "/orientation").c_str(), H5T_IEEE_F64LE, four,
                    orientation_chunk),
      create_series(file, (group + "/world_vertices").c_str(), H5T_IEEE_F64LE, surface_shape,
                    surface_chunk)};
}

template <class T>
std::vector<T> read_whole(const hdf5::File& file, const std::string& name, hid_t memory_type,
                          std::vector<hsize_t>& shape, const std::string& what) {
  const Handle dataset = file.open(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), H5Dclose,
                                   fmt::format("{}: open {}", what, name));
  const Handle space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  const int rank = file.check(H5Sget_simple_extent_ndims(space.get()), what);
  shape.assign(static_cast<std::size_t>(rank), 0);
  file.check(H5Sget_simple_extent_dims(space.get(), shape.data(), nullptr), what);
  hsize_t count = 1;
  for (const hsize_t d : shape) count *= d;
  std::vector<T> values(count);
  if (count > 0)
    file.check(H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, file.collective(),
                       values.data()),
               fmt::format("{}: read {}", what, name));
  return values;
}

hsize_t frames_of(const hdf5::File& file, const Handle& dataset, const std::string& what) {
  const Handle space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  std::array<hsize_t, 4> extent{};
  file.check(H5Sget_simple_extent_dims(space.get(), extent.data(), nullptr), what);
  return extent[0];
}

// --- Per-node fields (docs/output.md, "Fields"): series of the grid's shape, written like the
// positions, each rank its block.

std::string field_path(const NodeField& field) { return "/fields/" + field.name; }

hsize_t components_of(const NodeField& field) { return field.vector ? 3 : 0; }

void check_field_names(const std::vector<NodeField>& fields) {
  for (std::size_t i = 0; i < fields.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (fields[i].name == fields[j].name)
        throw std::invalid_argument(
            fmt::format("two output fields are named '{}'", fields[i].name));
}

Handle create_field(const hdf5::File& file, const NodeField& field, int m, int n) {
  const std::string path = field_path(field);
  Handle dataset = create_series(file, path.c_str(), H5T_IEEE_F64LE,
                                 node_shape(m, n, components_of(field)),
                                 node_chunk(m, n, components_of(field)));
  file.write_attribute(dataset.get(), "units", field.units);
  return dataset;
}

// The shape of a dataset's frames: its extent without the first dimension.
std::vector<hsize_t> frame_shape_of(const hdf5::File& file, const Handle& dataset,
                                    const std::string& what) {
  const Handle space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  const int rank = file.check(H5Sget_simple_extent_ndims(space.get()), what);
  std::vector<hsize_t> extent(static_cast<std::size_t>(rank), 0);
  file.check(H5Sget_simple_extent_dims(space.get(), extent.data(), nullptr), what);
  if (!extent.empty()) extent.erase(extent.begin());
  return extent;
}

std::string field_names(const std::vector<std::string>& names) {
  return names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace

// Members close in reverse order: datasets before the file.
struct FrameWriter::Datasets {
  Handle positions;
  Handle time;
  Handle step;
  std::vector<SolidSeries> solids{};
  std::vector<Handle> fields{};
};

std::string xdmf_path(const std::string& h5_path) {
  return std::filesystem::path(h5_path).replace_extension(".xmf").string();
}

FrameWriter::FrameWriter(const std::string& h5_path, const Block& block,
                         const std::string& scene_text, const std::string& integrator,
                         const std::string& version, const std::vector<std::string>& overrides,
                         const std::vector<SolidOutline>& solids,
                         const std::vector<NodeField>& fields)
    : block_(&block),
      h5_path_(h5_path),
      xmf_path_(xdmf_path(h5_path)),
      rank_(rank_in(block.comm)),
      solids_(solids),
      fields_(fields) {
  if (block.m < 1 || block.n < 1)
    throw std::runtime_error(fmt::format("HDF5 file '{}': grid {} x {} has no nodes to write",
                                         h5_path, block.m, block.n));
  for (std::size_t i = 0; i < solids.size(); ++i) check_outline(solids[i], i);
  check_field_names(fields);
  file_ = std::make_unique<hdf5::File>(h5_path, block.comm, hdf5::File::Mode::create);
  datasets_ = std::make_unique<Datasets>(Datasets{
      create_series(*file_, "/positions", H5T_IEEE_F64LE, node_shape(block.m, block.n, 3),
                    node_chunk(block.m, block.n, 3)),
      create_series(*file_, "/time", H5T_IEEE_F64LE, {}, series_chunk),
      create_series(*file_, "/step", H5T_STD_I64LE, {}, series_chunk)});
  file_->write_attribute("scene", scene_text);
  file_->write_attribute("integrator", integrator);
  file_->write_attribute("version", version);
  file_->write_attribute("overrides", join_lines(overrides));
  if (!solids.empty()) create_group(*file_, "/solids");
  for (std::size_t i = 0; i < solids.size(); ++i)
    datasets_->solids.push_back(create_solid(*file_, i, solids[i], rank_ == 0));
  if (!fields.empty()) create_group(*file_, "/fields");
  for (const NodeField& field : fields)
    datasets_->fields.push_back(create_field(*file_, field, block.m, block.n));
  file_->flush();
}

FrameWriter::FrameWriter(const std::string& h5_path, const Block& block, long step,
                         const std::string& scene_text, long last_scheduled_frame,
                         double last_scheduled_time, const std::vector<SolidOutline>& solids,
                         const std::vector<NodeField>& fields)
    : block_(&block),
      h5_path_(h5_path),
      xmf_path_(xdmf_path(h5_path)),
      rank_(rank_in(block.comm)),
      solids_(solids),
      fields_(fields) {
  check_field_names(fields);
  file_ = std::make_unique<hdf5::File>(h5_path, block.comm, hdf5::File::Mode::read_write);
  const std::string what = "reopen for a restart";
  auto open = [&](const char* name) {
    return file_->open(H5Dopen2(file_->get(), name, H5P_DEFAULT), H5Dclose,
                       fmt::format("{}: open {}", what, name));
  };
  datasets_ = std::make_unique<Datasets>(Datasets{open("/positions"), open("/time"), open("/step")});
  // A restart continues only the output of the same run: checked before anything is changed.
  auto refuse = [&](const std::string& why) {
    throw std::runtime_error(
        fmt::format("{}: {}; a restart continues only the output of the run it restarts "
                    "(name another --output to start a new file)",
                    h5_path, why));
  };
  if (file_->read_string_attribute("scene") != scene_text)
    refuse("it was written for another scene text");
  {
    const Handle space = file_->open(H5Dget_space(datasets_->positions.get()), H5Sclose, what);
    std::array<hsize_t, 4> extent{};
    file_->check(H5Sget_simple_extent_dims(space.get(), extent.data(), nullptr), what);
    if (extent[1] != static_cast<hsize_t>(block.m) || extent[2] != static_cast<hsize_t>(block.n))
      refuse(fmt::format("its frames are {} x {} nodes, this run's {} x {}", extent[1],
                         extent[2], block.m, block.n));
  }
  const auto steps = read_series<std::int64_t>(*file_, datasets_->step, H5T_NATIVE_INT64, what);
  const auto times = read_series<double>(*file_, datasets_->time, H5T_NATIVE_DOUBLE, what);
  for (std::size_t f = 0; f < steps.size() && f < times.size() && steps[f] <= step; ++f) {
    steps_.push_back(steps[f]);
    times_.push_back(times[f]);
  }
  if (steps_.empty() || steps_.back() < last_scheduled_frame)
    refuse(fmt::format("it holds frames up to step {}, and the checkpoint at step {} follows the "
                       "frame of step {}: the frames between would be missing",
                       steps_.empty() ? -1 : steps_.back(), step, last_scheduled_frame));
  if (times_.back() < last_scheduled_time)
    refuse(fmt::format("it holds frames up to t = {} s, and the checkpoint at step {} follows the "
                       "frame of t = {} s: the frames between would be missing",
                       times_.back(), step, last_scheduled_time));
  const auto kept = static_cast<hsize_t>(steps_.size());
  // The same solids, each with every kept frame (a run killed inside a frame's write may have
  // extended some series and not others).
  const bool has_solids = file_->check(H5Lexists(file_->get(), "solids", H5P_DEFAULT), what) > 0;
  if (has_solids && solids.empty()) refuse("it holds solids and this run has none");
  if (!solids.empty()) {
    if (!has_solids) refuse(fmt::format("it holds no solids and this run has {}", solids.size()));
    H5G_info_t info{};
    file_->check(H5Gget_info_by_name(file_->get(), "solids", &info, H5P_DEFAULT), what);
    if (info.nlinks != solids.size())
      refuse(fmt::format("it holds {} solids, this run {}", info.nlinks, solids.size()));
  }
  for (std::size_t i = 0; i < solids.size(); ++i) {
    const std::string group = solid_group(i);
    if (H5Lexists(file_->get(), group.c_str(), H5P_DEFAULT) <= 0)
      refuse(fmt::format("it has no solid {} ({})", i, group));
    {
      const Handle handle = file_->open(H5Gopen2(file_->get(), group.c_str(), H5P_DEFAULT),
                                        H5Gclose, fmt::format("{}: open {}", what, group));
      const std::string name = file_->read_string_attribute(handle.get(), "name");
      if (name != solids[i].name)
        refuse(fmt::format("its solid {} is '{}', this run's '{}'", i, name, solids[i].name));
    }
    std::vector<hsize_t> shape;
    const auto vertices = read_whole<double>(*file_, group + "/vertices", H5T_NATIVE_DOUBLE,
                                             shape, what);
    const auto triangles = read_whole<std::int32_t>(*file_, group + "/triangles",
                                                    H5T_NATIVE_INT32, shape, what);
    if (vertices != flattened(solids[i].surface.vertices) ||
        triangles != flattened(solids[i].surface.triangles))
      refuse(fmt::format("the surface of its solid {} ('{}') is not this run's", i,
                         solids[i].name));
    datasets_->solids.push_back(SolidSeries{open((group + "/position").c_str()),
                                            open((group + "/orientation").c_str()),
                                            open((group + "/world_vertices").c_str())});
  }
  // The same fields, each of this grid's shape and in the same units: another --set
  // output.fields than the run's would leave some series a frame short or without frames.
  {
    std::vector<std::string> held;
    if (file_->check(H5Lexists(file_->get(), "fields", H5P_DEFAULT), what) > 0) {
      H5G_info_t info{};
      file_->check(H5Gget_info_by_name(file_->get(), "fields", &info, H5P_DEFAULT), what);
      for (hsize_t i = 0; i < info.nlinks; ++i) {
        const ssize_t size = H5Lget_name_by_idx(file_->get(), "fields", H5_INDEX_NAME,
                                                H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
        file_->check(static_cast<hid_t>(size), what + " (field names)");
        std::string name(static_cast<std::size_t>(size) + 1, '\0');
        file_->check(H5Lget_name_by_idx(file_->get(), "fields", H5_INDEX_NAME, H5_ITER_INC, i,
                                        name.data(), name.size(), H5P_DEFAULT),
                     what + " (field names)");
        name.resize(static_cast<std::size_t>(size));
        held.push_back(name);
      }
    }
    std::vector<std::string> wanted;
    for (const NodeField& field : fields) wanted.push_back(field.name);
    std::vector<std::string> wanted_sorted = wanted;
    std::ranges::sort(wanted_sorted);
    if (held != wanted_sorted)
      refuse(fmt::format("it holds the fields {} and this run writes {} (output.fields, or its "
                         "default by the grid's size: docs/output.md)",
                         field_names(held), field_names(wanted_sorted)));
  }
  for (const NodeField& field : fields) {
    const std::string path = field_path(field);
    Handle dataset = open(path.c_str());
    if (frame_shape_of(*file_, dataset, what) != node_shape(block.m, block.n, components_of(field)))
      refuse(fmt::format("its {} is not of this grid's shape", path));
    if (file_->read_string_attribute(dataset.get(), "units") != field.units)
      refuse(fmt::format("its {} is in '{}', this run's in '{}'", path,
                         file_->read_string_attribute(dataset.get(), "units"), field.units));
    datasets_->fields.push_back(std::move(dataset));
  }

  auto check_frames = [&](const Handle& dataset, const std::string& name) {
    const hsize_t frames = frames_of(*file_, dataset, what);
    if (frames < kept)
      refuse(fmt::format("its {} holds {} frames, fewer than the {} it keeps", name, frames, kept));
  };
  check_frames(datasets_->positions, "/positions");
  for (std::size_t i = 0; i < datasets_->solids.size(); ++i) {
    const SolidSeries& solid = datasets_->solids[i];
    check_frames(solid.position, solid_group(i) + "/position");
    check_frames(solid.orientation, solid_group(i) + "/orientation");
    check_frames(solid.world_vertices, solid_group(i) + "/world_vertices");
  }
  for (std::size_t i = 0; i < fields.size(); ++i)
    check_frames(datasets_->fields[i], field_path(fields[i]));

  resize_series(*file_, datasets_->positions, kept, what);
  resize_series(*file_, datasets_->time, kept, what);
  resize_series(*file_, datasets_->step, kept, what);
  for (const SolidSeries& solid : datasets_->solids) {
    resize_series(*file_, solid.position, kept, what);
    resize_series(*file_, solid.orientation, kept, what);
    resize_series(*file_, solid.world_vertices, kept, what);
  }
  for (const Handle& field : datasets_->fields) resize_series(*file_, field, kept, what);
  file_->write_attribute("status", std::string("running (restarted)"));
  file_->flush();
  // Written whole once, for the frames kept: it may describe the dropped ones, or be the partial
  // file of a run killed while appending.
  if (rank_ == 0)
    xdmf_ = std::make_unique<XdmfFile>(xmf_path_, h5_filename(), block.m, block.n, times_,
                                       xdmf_solids(), xdmf_fields());
}

FrameWriter::~FrameWriter() = default;

void FrameWriter::write_frame(long step, double time, const Field<Vec3>& positions,
                              const std::vector<Pose>& solid_poses,
                              const std::vector<NodeFieldValues>& field_values) {
  const auto frame = static_cast<hsize_t>(steps_.size());
  const std::string what = fmt::format("write frame {}", frame);
  if (solid_poses.size() != solids_.size())
    throw std::invalid_argument(fmt::format("HDF5 file '{}': {}: {} solid poses for {} solids",
                                            h5_path_, what, solid_poses.size(), solids_.size()));
  if (field_values.size() != fields_.size())
    throw std::invalid_argument(fmt::format("HDF5 file '{}': {}: {} field values for {} fields",
                                            h5_path_, what, field_values.size(), fields_.size()));
  for (std::size_t i = 0; i < fields_.size(); ++i)
    if (std::holds_alternative<const Field<Vec3>*>(field_values[i]) != fields_[i].vector)
      throw std::invalid_argument(fmt::format(
          "HDF5 file '{}': {}: field '{}' is a {}, given a {}", h5_path_, what, fields_[i].name,
          fields_[i].vector ? "vector" : "scalar", fields_[i].vector ? "scalar" : "vector"));
  const std::int64_t step_value = step;
  resize_series(*file_, datasets_->positions, frame + 1, what);
  resize_series(*file_, datasets_->time, frame + 1, what);
  resize_series(*file_, datasets_->step, frame + 1, what);
  for (const SolidSeries& solid : datasets_->solids) {
    resize_series(*file_, solid.position, frame + 1, what);
    resize_series(*file_, solid.orientation, frame + 1, what);
    resize_series(*file_, solid.world_vertices, frame + 1, what);
  }
  for (const Handle& field : datasets_->fields) resize_series(*file_, field, frame + 1, what);
  const std::array<hsize_t, 1> at{frame};
  file_->write_block(datasets_->positions.get(), positions, at, what + " of /positions");
  for (std::size_t i = 0; i < fields_.size(); ++i)
    std::visit(
        [&](const auto* values) {
          file_->write_block(datasets_->fields[i].get(), *values, at,
                             what + " of " + field_path(fields_[i]));
        },
        field_values[i]);
  write_series_value(*file_, datasets_->time, frame, H5T_NATIVE_DOUBLE, &time, rank_ == 0,
                     what + " of /time");
  write_series_value(*file_, datasets_->step, frame, H5T_NATIVE_INT64, &step_value, rank_ == 0,
                     what + " of /step");
  for (std::size_t i = 0; i < solids_.size(); ++i) {
    const Pose& pose = solid_poses[i];
    const SolidSeries& solid = datasets_->solids[i];
    const std::string of = fmt::format("{} of {}/", what, solid_group(i));
    const std::array<double, 3> position{pose.position.x, pose.position.y, pose.position.z};
    const std::array<double, 4> orientation{pose.orientation.w, pose.orientation.x,
                                            pose.orientation.y, pose.orientation.z};
    const std::vector<double> world = placed_vertices(pose, solids_[i].surface.vertices);
    const std::array<hsize_t, 2> row{frame, 0};
    const std::array<hsize_t, 2> three{1, 3}, four{1, 4};
    write_replicated(*file_, solid.position, row, three, H5T_NATIVE_DOUBLE, position.data(),
                     rank_ == 0, of + "position");
    write_replicated(*file_, solid.orientation, row, four, H5T_NATIVE_DOUBLE,
                     orientation.data(), rank_ == 0, of + "orientation");
    const std::array<hsize_t, 3> surface_at{frame, 0, 0};
    const std::array<hsize_t, 3> surface_count{1, solids_[i].surface.vertices.size(), 3};
    write_replicated(*file_, solid.world_vertices, surface_at, surface_count, H5T_NATIVE_DOUBLE,
                     world.data(), rank_ == 0, of + "world_vertices");
  }
  file_->flush();

  times_.push_back(time);
  steps_.push_back(step);
  if (rank_ != 0) return;
  if (xdmf_)
    xdmf_->append(time);
  else
    xdmf_ = std::make_unique<XdmfFile>(xmf_path_, h5_filename(), block_->m, block_->n, times_,
                                       xdmf_solids(), xdmf_fields());
}

std::vector<XdmfSolid> FrameWriter::xdmf_solids() const {
  std::vector<XdmfSolid> solids;
  for (const SolidOutline& solid : solids_)
    solids.push_back(XdmfSolid{solid.name, static_cast<long>(solid.surface.vertices.size()),
                               static_cast<long>(solid.surface.triangles.size())});
  return solids;
}

std::vector<XdmfField> FrameWriter::xdmf_fields() const {
  std::vector<XdmfField> fields;
  for (const NodeField& field : fields_) fields.push_back(XdmfField{field.name, field.vector});
  return fields;
}

std::string FrameWriter::h5_filename() const {
  return std::filesystem::path(h5_path_).filename().string();
}

void FrameWriter::set_attribute(const std::string& name, const std::string& value) {
  file_->write_attribute(name, value);
  file_->flush();
}

}  // namespace cosserat
