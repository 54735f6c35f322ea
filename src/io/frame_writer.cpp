#include "cosserat/io/frame_writer.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>

#include <fmt/format.h>

#include "cosserat/io/xdmf.hpp"
#include "hdf5_file.hpp"

namespace cosserat {

using hdf5::Handle;

namespace {

// HDF5 refuses chunks of 4 GiB or more. One frame is one chunk, so that appending a frame
// touches one chunk, unless the frame is that large; then it is split into bands of rows k
// (and of columns l only if a single row is too large).
std::array<hsize_t, 4> positions_chunk(int m, int n) {
  constexpr hsize_t max_chunk_bytes = (hsize_t{1} << 32) - 1;
  constexpr hsize_t max_nodes = max_chunk_bytes / (3 * sizeof(double));
  const hsize_t columns = std::min<hsize_t>(static_cast<hsize_t>(n), max_nodes);
  const hsize_t rows = std::min<hsize_t>(static_cast<hsize_t>(m), max_nodes / columns);
  return {1, rows, columns, 3};
}

// Long runs write thousands of frames; a chunk of this many times or steps keeps the index of
// the one-dimensional datasets small.
constexpr std::array<hsize_t, 1> series_chunk{1024};

std::array<hsize_t, 3> node_shape(int m, int n) {
  return {static_cast<hsize_t>(m), static_cast<hsize_t>(n), 3};
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

// Writes one value of a one-dimensional series at `frame`: rank 0 writes, the others take part
// in the collective call with an empty selection.
void write_series_value(const hdf5::File& file, const Handle& dataset, hsize_t frame,
                        hid_t memory_type, const void* value, bool writer,
                        const std::string& what) {
  const Handle file_space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  const hsize_t one = 1;
  const Handle memory_space = file.open(H5Screate_simple(1, &one, nullptr), H5Sclose, what);
  if (writer) {
    file.check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &frame, nullptr, &one,
                                   nullptr),
               what + " (select)");
  } else {
    file.check(H5Sselect_none(file_space.get()), what + " (select)");
    file.check(H5Sselect_none(memory_space.get()), what + " (select)");
  }
  file.check(H5Dwrite(dataset.get(), memory_type, memory_space.get(), file_space.get(),
                      file.collective(), value),
             what);
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

}  // namespace

// Members close in reverse order: datasets before the file.
struct FrameWriter::Datasets {
  Handle positions;
  Handle time;
  Handle step;
};

std::string xdmf_path(const std::string& h5_path) {
  return std::filesystem::path(h5_path).replace_extension(".xmf").string();
}

FrameWriter::FrameWriter(const std::string& h5_path, const Block& block,
                         const std::string& scene_text, const std::string& integrator,
                         const std::string& version, const std::vector<std::string>& overrides)
    : block_(&block),
      h5_path_(h5_path),
      xmf_path_(xdmf_path(h5_path)),
      rank_(rank_in(block.comm)) {
  if (block.m < 1 || block.n < 1)
    throw std::runtime_error(fmt::format("HDF5 file '{}': grid {} x {} has no nodes to write",
                                         h5_path, block.m, block.n));
  file_ = std::make_unique<hdf5::File>(h5_path, block.comm, hdf5::File::Mode::create);
  datasets_ = std::make_unique<Datasets>(Datasets{
      create_series(*file_, "/positions", H5T_IEEE_F64LE, node_shape(block.m, block.n),
                    positions_chunk(block.m, block.n)),
      create_series(*file_, "/time", H5T_IEEE_F64LE, {}, series_chunk),
      create_series(*file_, "/step", H5T_STD_I64LE, {}, series_chunk)});
  file_->write_attribute("scene", scene_text);
  file_->write_attribute("integrator", integrator);
  file_->write_attribute("version", version);
  file_->write_attribute("overrides", join_lines(overrides));
  file_->flush();
}

FrameWriter::FrameWriter(const std::string& h5_path, const Block& block, long step,
                         const std::string& scene_text, long last_scheduled_frame,
                         double last_scheduled_time)
    : block_(&block),
      h5_path_(h5_path),
      xmf_path_(xdmf_path(h5_path)),
      rank_(rank_in(block.comm)) {
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
  resize_series(*file_, datasets_->positions, kept, what);
  resize_series(*file_, datasets_->time, kept, what);
  resize_series(*file_, datasets_->step, kept, what);
  file_->write_attribute("status", std::string("running (restarted)"));
  file_->flush();
  // Written whole once, for the frames kept: it may describe the dropped ones, or be the partial
  // file of a run killed while appending.
  if (rank_ == 0)
    xdmf_ = std::make_unique<XdmfFile>(xmf_path_, h5_filename(), block.m, block.n, times_);
}

FrameWriter::~FrameWriter() = default;

void FrameWriter::write_frame(long step, double time, const Field<Vec3>& positions) {
  const auto frame = static_cast<hsize_t>(steps_.size());
  const std::string what = fmt::format("write frame {}", frame);
  const std::int64_t step_value = step;
  resize_series(*file_, datasets_->positions, frame + 1, what);
  resize_series(*file_, datasets_->time, frame + 1, what);
  resize_series(*file_, datasets_->step, frame + 1, what);
  const std::array<hsize_t, 1> at{frame};
  file_->write_block(datasets_->positions.get(), positions, at, what + " of /positions");
  write_series_value(*file_, datasets_->time, frame, H5T_NATIVE_DOUBLE, &time, rank_ == 0,
                     what + " of /time");
  write_series_value(*file_, datasets_->step, frame, H5T_NATIVE_INT64, &step_value, rank_ == 0,
                     what + " of /step");
  file_->flush();

  times_.push_back(time);
  steps_.push_back(step);
  if (rank_ != 0) return;
  if (xdmf_)
    xdmf_->append(time);
  else
    xdmf_ = std::make_unique<XdmfFile>(xmf_path_, h5_filename(), block_->m, block_->n, times_);
}

std::string FrameWriter::h5_filename() const {
  return std::filesystem::path(h5_path_).filename().string();
}

void FrameWriter::set_attribute(const std::string& name, const std::string& value) {
  file_->write_attribute(name, value);
  file_->flush();
}

}  // namespace cosserat
