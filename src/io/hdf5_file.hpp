#pragma once
// What the output writer and the checkpoints share: an HDF5 file opened by every rank of a
// communicator through MPI-IO, handles that close themselves, failures as exceptions naming the
// file, and the collective write and read of a block's nodes as its hyperslab of an [m][n][3]
// (or [m][n]) array. Private to src/io: hdf5.h stays out of the public headers.

#include <hdf5.h>

#include <cstdint>
#include <exception>
#include <span>
#include <string>
#include <vector>
#include <utility>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat::hdf5 {

// Whether a process runs the files of more than one rank. Closing an HDF5 object of such a file
// is collective: while an exception unwinds on one rank the others are elsewhere, so a close
// would hang every rank. Handles then stay open, and the driver ends every rank with MPI_Abort
// (docs/output.md, "When a run fails").
inline bool& shared_by_ranks() {
  static bool shared = false;
  return shared;
}

// An HDF5 identifier with the close function of its kind.
class Handle {
 public:
  using Close = herr_t (*)(hid_t);

  Handle() = default;
  Handle(hid_t id, Close close) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0 && !(shared_by_ranks() && std::uncaught_exceptions() > 0)) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept
      : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Handle& operator=(Handle&& other) noexcept {
    std::swap(id_, other.id_);
    std::swap(close_, other.close_);
    return *this;
  }

  hid_t get() const { return id_; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Close close_ = nullptr;
};

class File {
 public:
  enum class Mode { create, read, read_write };

  // Collective over comm. Files are created in the HDF5 1.8 format: the 1.10 superblock
  // carries an "open for writing" flag that makes the file of a killed run refuse to open
  // until h5clear is run on it.
  File(const std::string& path, MPI_Comm comm, Mode mode);

  const std::string& path() const { return path_; }
  hid_t get() const { return file_.get(); }

  [[noreturn]] void fail(const std::string& operation) const;
  hid_t check(hid_t id, const std::string& operation) const {
    if (id < 0) fail(operation);
    return id;
  }
  Handle open(hid_t id, Handle::Close close, const std::string& operation) const {
    return Handle(check(id, operation), close);
  }

  // Root attributes; collective when written (every rank passes the same value).
  void write_attribute(const std::string& name, const std::string& value) const;
  void write_attribute(const std::string& name, std::int64_t value) const;
  void write_attribute(const std::string& name, double value) const;
  void write_attribute(const std::string& name, const std::vector<double>& values) const;
  std::string read_string_attribute(const std::string& name) const;
  // The same on a group or dataset of the file.
  void write_attribute(hid_t object, const std::string& name, const std::string& value) const;
  std::string read_string_attribute(hid_t object, const std::string& name) const;
  bool has_attribute(const std::string& name) const;
  std::int64_t read_int_attribute(const std::string& name) const;
  double read_double_attribute(const std::string& name) const;
  std::vector<double> read_doubles_attribute(const std::string& name) const;

  // Transfer property lists for collective and independent I/O.
  hid_t collective() const { return collective_.get(); }
  hid_t independent() const { return H5P_DEFAULT; }

  // Every rank writes (reads) its block's owned nodes as the slab [k0:k1, l0:l1, 0:3] of the
  // dataset, at index `frame` of a leading frame dimension when the dataset has one.
  void write_block(hid_t dataset, const Field<Vec3>& field, std::span<const hsize_t> frame,
                   const std::string& what) const;
  // The same for one value per node: the slab [k0:k1, l0:l1] of an [frames...][m][n] dataset.
  void write_block(hid_t dataset, const Field<double>& field, std::span<const hsize_t> frame,
                   const std::string& what) const;
  void read_block(hid_t dataset, Field<Vec3>& field, const std::string& what) const;

  void flush() const { check(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), "flush"); }

 private:
  std::string path_;
  Handle file_;
  Handle collective_;
};

}  // namespace cosserat::hdf5
