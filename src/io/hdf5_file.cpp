#include "hdf5_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <optional>
#include <stdexcept>
#include <vector>

namespace cosserat::hdf5 {

namespace {

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

}  // namespace

File::File(const std::string& path, MPI_Comm comm, Mode mode) : path_(path) {
  if (size_of(comm) > 1) shared_by_ranks() = true;
  // Failures become exceptions carrying HDF5's innermost message; the default handler would
  // also print the whole stack to stderr, from every rank.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const Handle access = open(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "create file access list");
  check(H5Pset_fapl_mpio(access.get(), comm, MPI_INFO_NULL), "select MPI-IO");
  check(H5Pset_libver_bounds(access.get(), H5F_LIBVER_EARLIEST, H5F_LIBVER_V18),
        "set format bounds");
  switch (mode) {
    case Mode::create:
      file_ = open(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access.get()), H5Fclose,
                   "create file");
      break;
    case Mode::read:
      file_ = open(H5Fopen(path.c_str(), H5F_ACC_RDONLY, access.get()), H5Fclose, "open file");
      break;
    case Mode::read_write:
      file_ = open(H5Fopen(path.c_str(), H5F_ACC_RDWR, access.get()), H5Fclose, "open file");
      break;
  }
  collective_ = open(H5Pcreate(H5P_DATASET_XFER), H5Pclose, "create transfer list");
  check(H5Pset_dxpl_mpio(collective_.get(), H5FD_MPIO_COLLECTIVE), "select collective I/O");
}

void File::fail(const std::string& operation) const {
  throw std::runtime_error(
      fmt::format("HDF5 file '{}': {} failed: {}", path_, operation, innermost_hdf5_error()));
}

namespace {

// Replaces an attribute of a fixed type of `object` (the file: its root) with a scalar value
// or, with `count`, a one-dimensional array of that many values.
void write_values(const File& file, hid_t object, const std::string& name, hid_t file_type,
                  hid_t memory_type, const void* value, std::optional<hsize_t> count = {}) {
  const std::string what = fmt::format("write attribute '{}'", name);
  const htri_t exists = H5Aexists(object, name.c_str());
  file.check(exists, what + " (look up)");
  if (exists > 0) file.check(H5Adelete(object, name.c_str()), what + " (delete old)");
  const Handle space = file.open(count ? H5Screate_simple(1, &*count, nullptr)
                                       : H5Screate(H5S_SCALAR),
                                 H5Sclose, what);
  const Handle attribute = file.open(
      H5Acreate2(object, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose, what);
  file.check(H5Awrite(attribute.get(), memory_type, value), what);
}

Handle string_type(const File& file, const std::string& what) {
  Handle type = file.open(H5Tcopy(H5T_C_S1), H5Tclose, what);
  file.check(H5Tset_size(type.get(), H5T_VARIABLE), what + " (type)");
  file.check(H5Tset_cset(type.get(), H5T_CSET_UTF8), what + " (type)");
  return type;
}

}  // namespace

// Variable-length UTF-8, which h5py reads back as str (fixed-length strings come back as bytes).
// The text lives in the global heap, so a scene of any length fits; an attribute stored in the
// object header is limited to 64 KiB.
void File::write_attribute(const std::string& name, const std::string& value) const {
  write_attribute(file_.get(), name, value);
}

void File::write_attribute(hid_t object, const std::string& name,
                           const std::string& value) const {
  const Handle type = string_type(*this, fmt::format("write attribute '{}'", name));
  const char* text = value.c_str();
  write_values(*this, object, name, type.get(), type.get(), &text);
}

void File::write_attribute(const std::string& name, std::int64_t value) const {
  write_values(*this, file_.get(), name, H5T_STD_I64LE, H5T_NATIVE_INT64, &value);
}

void File::write_attribute(const std::string& name, double value) const {
  write_values(*this, file_.get(), name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

void File::write_attribute(const std::string& name, const std::vector<double>& values) const {
  write_values(*this, file_.get(), name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(),
               values.size());
}

namespace {

Handle open_attribute(const File& file, hid_t object, const std::string& name,
                      const std::string& what) {
  return file.open(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose, what);
}

}  // namespace

std::string File::read_string_attribute(const std::string& name) const {
  return read_string_attribute(file_.get(), name);
}

std::string File::read_string_attribute(hid_t object, const std::string& name) const {
  const std::string what = fmt::format("read attribute '{}'", name);
  const Handle attribute = open_attribute(*this, object, name, what);
  const Handle type = string_type(*this, what);
  char* text = nullptr;
  check(H5Aread(attribute.get(), type.get(), &text), what);
  std::string value = text != nullptr ? text : "";
  H5free_memory(text);
  return value;
}

std::int64_t File::read_int_attribute(const std::string& name) const {
  const std::string what = fmt::format("read attribute '{}'", name);
  const Handle attribute = open_attribute(*this, file_.get(), name, what);
  std::int64_t value = 0;
  check(H5Aread(attribute.get(), H5T_NATIVE_INT64, &value), what);
  return value;
}

bool File::has_attribute(const std::string& name) const {
  const htri_t exists = H5Aexists(file_.get(), name.c_str());
  check(exists, fmt::format("look for attribute '{}'", name));
  return exists > 0;
}

std::vector<double> File::read_doubles_attribute(const std::string& name) const {
  const std::string what = fmt::format("read attribute '{}'", name);
  const Handle attribute = open_attribute(*this, file_.get(), name, what);
  const Handle space = open(H5Aget_space(attribute.get()), H5Sclose, what);
  const hssize_t size = H5Sget_simple_extent_npoints(space.get());
  check(static_cast<hid_t>(size), what + " (size)");
  std::vector<double> values(static_cast<std::size_t>(size));
  check(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, values.data()), what);
  return values;
}

double File::read_double_attribute(const std::string& name) const {
  const std::string what = fmt::format("read attribute '{}'", name);
  const Handle attribute = open_attribute(*this, file_.get(), name, what);
  double value = 0.0;
  check(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &value), what);
  return value;
}

namespace {

// The block's slab of an [frames...][m][n][components] dataset (no last dimension when
// `components` is 0) and a matching memory space.
struct Slab {
  Handle file_space, memory_space;
};

Slab block_slab(const File& file, hid_t dataset, const Block& b, std::span<const hsize_t> frame,
                hsize_t components, const std::string& what) {
  std::array<hsize_t, 4> start{}, count{};
  std::size_t d = 0;
  for (const hsize_t f : frame) {
    start[d] = f;
    count[d++] = 1;
  }
  start[d] = static_cast<hsize_t>(b.k0);
  count[d++] = static_cast<hsize_t>(b.owned_k());
  start[d] = static_cast<hsize_t>(b.l0);
  count[d++] = static_cast<hsize_t>(b.owned_l());
  if (components > 0) {
    start[d] = 0;
    count[d++] = components;
  }
  Slab slab{file.open(H5Dget_space(dataset), H5Sclose, what),
            file.open(H5Screate_simple(static_cast<int>(d), count.data(), nullptr), H5Sclose, what)};
  file.check(H5Sselect_hyperslab(slab.file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                 count.data(), nullptr),
             what + " (select)");
  return slab;
}

// Values per node of a field as the file holds them: three for a vector, one (and no last
// dimension) for a scalar.
template <class T>
constexpr hsize_t components_of = 0;
template <>
constexpr hsize_t components_of<Vec3> = 3;

void append(std::vector<double>& values, double value) { values.push_back(value); }
void append(std::vector<double>& values, const Vec3& p) {
  values.insert(values.end(), {p.x, p.y, p.z});
}

// The file's order is l fastest, the field's k fastest: one transposing copy each way.
template <class T>
void write_owned(const File& file, hid_t dataset, const Field<T>& field,
                 std::span<const hsize_t> frame, const std::string& what) {
  const Block& b = field.block();
  const Slab slab = block_slab(file, dataset, b, frame, components_of<T>, what);
  std::vector<double> values;
  values.reserve(std::max<std::size_t>(components_of<T>, 1) *
                 static_cast<std::size_t>(b.owned_k()) * b.owned_l());
  for (int k = b.k0; k < b.k1; ++k)
    for (int l = b.l0; l < b.l1; ++l) append(values, field(k, l));
  file.check(H5Dwrite(dataset, H5T_NATIVE_DOUBLE, slab.memory_space.get(), slab.file_space.get(),
                      file.collective(), values.data()),
             what);
}

}  // namespace

void File::write_block(hid_t dataset, const Field<Vec3>& field, std::span<const hsize_t> frame,
                       const std::string& what) const {
  write_owned(*this, dataset, field, frame, what);
}

void File::write_block(hid_t dataset, const Field<double>& field, std::span<const hsize_t> frame,
                       const std::string& what) const {
  write_owned(*this, dataset, field, frame, what);
}

void File::read_block(hid_t dataset, Field<Vec3>& field, const std::string& what) const {
  const Block& b = field.block();
  const Slab slab = block_slab(*this, dataset, b, {}, components_of<Vec3>, what);
  std::vector<double> values(3 * static_cast<std::size_t>(b.owned_k()) * b.owned_l());
  check(H5Dread(dataset, H5T_NATIVE_DOUBLE, slab.memory_space.get(), slab.file_space.get(),
                collective(), values.data()),
        what);
  std::size_t at = 0;
  for (int k = b.k0; k < b.k1; ++k)
    for (int l = b.l0; l < b.l1; ++l) {
      field(k, l) = Vec3{values[at], values[at + 1], values[at + 2]};
      at += 3;
    }
}

}  // namespace cosserat::hdf5
