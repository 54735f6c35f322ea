#include "cosserat/io/frame_writer.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "cosserat/io/xdmf.hpp"

namespace cosserat {
namespace {

// An HDF5 identifier that closes itself. Each kind of id has its own close function, so the
// handle carries it.
class Handle {
 public:
  using Close = herr_t (*)(hid_t);

  Handle(hid_t id, Close close) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept
      : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Handle& operator=(Handle&&) = delete;

  hid_t get() const { return id_; }

 private:
  hid_t id_;
  Close close_;
};

herr_t keep_innermost(unsigned depth, const H5E_error2_t* error, void* description) {
  if (depth == 0 && error->desc != nullptr) *static_cast<std::string*>(description) = error->desc;
  return 0;
}

// The most specific message on HDF5's error stack (walking upward starts where the error was
// detected), e.g. the operating system's reason a file could not be created.
std::string innermost_hdf5_error() {
  std::string description = "no detail from HDF5";
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, keep_innermost, &description);
  return description;
}

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

}  // namespace

// Everything that speaks HDF5. Members close in reverse order: datasets before the file.
struct FrameWriter::Hdf5Output {
  std::string path;
  Handle file;
  Handle positions;
  Handle time;
  Handle step;

  Hdf5Output(const std::string& h5_path, int m, int n);

  [[noreturn]] void fail(const std::string& operation) const {
    throw std::runtime_error(
        fmt::format("HDF5 file '{}': {} failed: {}", path, operation, innermost_hdf5_error()));
  }
  hid_t check(hid_t id, const std::string& operation) const {
    if (id < 0) fail(operation);
    return id;
  }
  Handle open(hid_t id, Handle::Close close, const std::string& operation) const {
    return Handle(check(id, operation), close);
  }

  Handle create_file() const;
  Handle create_series(const char* name, hid_t file_type, std::span<const hsize_t> frame_shape,
                       std::span<const hsize_t> chunk) const;
  void append(const Handle& dataset, const char* name, hsize_t frame,
              std::span<const hsize_t> frame_shape, hid_t memory_type, const void* values) const;
  void write_string_attribute(const std::string& name, const std::string& value) const;
  void flush() const { check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "flush"); }
};

FrameWriter::Hdf5Output::Hdf5Output(const std::string& h5_path, int m, int n)
    : path(h5_path),
      file(create_file()),
      positions(create_series("/positions", H5T_IEEE_F64LE, node_shape(m, n),
                              positions_chunk(m, n))),
      time(create_series("/time", H5T_IEEE_F64LE, {}, series_chunk)),
      step(create_series("/step", H5T_STD_I64LE, {}, series_chunk)) {}

Handle FrameWriter::Hdf5Output::create_file() const {
  const Handle access = open(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "create file access list");
  // The 1.10 format's superblock carries an "open for writing" flag that makes the file of a
  // killed run refuse to open until h5clear is run on it; capping the format at 1.8 keeps that
  // flag out (and the file readable by any HDF5 since 2008).
  check(H5Pset_libver_bounds(access.get(), H5F_LIBVER_EARLIEST, H5F_LIBVER_V18),
        "set format bounds");
  return open(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get()), H5Fclose,
              "create file");
}

// A dataset of frames: the first dimension is unlimited and grows by one per written frame.
Handle FrameWriter::Hdf5Output::create_series(const char* name, hid_t file_type,
                                              std::span<const hsize_t> frame_shape,
                                              std::span<const hsize_t> chunk) const {
  std::array<hsize_t, 4> dims{0, 0, 0, 0};
  std::array<hsize_t, 4> max_dims{H5S_UNLIMITED, 0, 0, 0};
  std::ranges::copy(frame_shape, dims.begin() + 1);
  std::ranges::copy(frame_shape, max_dims.begin() + 1);
  const int rank = static_cast<int>(frame_shape.size()) + 1;
  const std::string what = fmt::format("create dataset {}", name);

  const Handle space = open(H5Screate_simple(rank, dims.data(), max_dims.data()), H5Sclose, what);
  const Handle properties = open(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, what);
  check(H5Pset_chunk(properties.get(), rank, chunk.data()), what + " (chunk shape)");
  return open(H5Dcreate2(file.get(), name, file_type, space.get(), H5P_DEFAULT, properties.get(),
                         H5P_DEFAULT),
              H5Dclose, what);
}

void FrameWriter::Hdf5Output::append(const Handle& dataset, const char* name, hsize_t frame,
                                     std::span<const hsize_t> frame_shape, hid_t memory_type,
                                     const void* values) const {
  std::array<hsize_t, 4> extent{frame + 1, 0, 0, 0};
  std::array<hsize_t, 4> start{frame, 0, 0, 0};
  std::array<hsize_t, 4> count{1, 0, 0, 0};
  std::ranges::copy(frame_shape, extent.begin() + 1);
  std::ranges::copy(frame_shape, count.begin() + 1);
  const int rank = static_cast<int>(frame_shape.size()) + 1;
  const std::string what = fmt::format("write frame {} of {}", frame, name);

  check(H5Dset_extent(dataset.get(), extent.data()), what + " (extend)");
  const Handle file_space = open(H5Dget_space(dataset.get()), H5Sclose, what);
  check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                            nullptr),
        what + " (select)");
  const Handle memory_space = open(H5Screate_simple(rank, count.data(), nullptr), H5Sclose, what);
  check(H5Dwrite(dataset.get(), memory_type, memory_space.get(), file_space.get(), H5P_DEFAULT,
                 values),
        what);
}

// Variable-length UTF-8, which h5py reads back as str (fixed-length strings come back as bytes).
// The text lives in the global heap, so a scene of any length fits; an attribute stored in the
// object header is limited to 64 KiB.
void FrameWriter::Hdf5Output::write_string_attribute(const std::string& name,
                                                     const std::string& value) const {
  const std::string what = fmt::format("write attribute '{}'", name);
  const htri_t exists = H5Aexists(file.get(), name.c_str());
  check(exists, what + " (look up)");
  if (exists > 0) check(H5Adelete(file.get(), name.c_str()), what + " (delete old)");

  const Handle type = open(H5Tcopy(H5T_C_S1), H5Tclose, what);
  check(H5Tset_size(type.get(), H5T_VARIABLE), what + " (type)");
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), what + " (type)");
  const Handle space = open(H5Screate(H5S_SCALAR), H5Sclose, what);
  const Handle attribute = open(
      H5Acreate2(file.get(), name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose, what);
  const char* text = value.c_str();
  check(H5Awrite(attribute.get(), type.get(), &text), what);
}

namespace {

std::string join_lines(const std::vector<std::string>& lines) {
  std::string joined;
  for (const std::string& line : lines) {
    if (!joined.empty()) joined += '\n';
    joined += line;
  }
  return joined;
}

std::filesystem::path xmf_path_for(const std::string& h5_path) {
  return std::filesystem::path(h5_path).replace_extension(".xmf");
}

}  // namespace

FrameWriter::FrameWriter(const std::string& h5_path, int m, int n, const std::string& scene_text,
                         const std::string& integrator, const std::string& version,
                         const std::vector<std::string>& overrides)
    : h5_path_(h5_path), xmf_path_(xmf_path_for(h5_path).string()), m_(m), n_(n) {
  if (m < 1 || n < 1) {
    throw std::runtime_error(
        fmt::format("HDF5 file '{}': grid {} x {} has no nodes to write", h5_path, m, n));
  }
  // Failures become exceptions carrying HDF5's innermost message; the default handler would
  // also print the whole stack to stderr, from every rank.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  output_ = std::make_unique<Hdf5Output>(h5_path, m, n);
  output_->write_string_attribute("scene", scene_text);
  output_->write_string_attribute("integrator", integrator);
  output_->write_string_attribute("version", version);
  output_->write_string_attribute("overrides", join_lines(overrides));
  output_->flush();
}

FrameWriter::~FrameWriter() = default;

void FrameWriter::write_frame(long step, double time, const double* positions) {
  const auto frame = static_cast<hsize_t>(times_.size());
  const std::int64_t step_value = step;
  output_->append(output_->positions, "/positions", frame, node_shape(m_, n_), H5T_NATIVE_DOUBLE,
                  positions);
  output_->append(output_->time, "/time", frame, {}, H5T_NATIVE_DOUBLE, &time);
  output_->append(output_->step, "/step", frame, {}, H5T_NATIVE_INT64, &step_value);
  output_->flush();

  times_.push_back(time);
  write_xdmf(xmf_path_, std::filesystem::path(h5_path_).filename().string(), m_, n_, times_);
}

void FrameWriter::set_attribute(const std::string& name, const std::string& value) {
  output_->write_string_attribute(name, value);
  output_->flush();
}

long FrameWriter::frames() const { return static_cast<long>(times_.size()); }

}  // namespace cosserat
