#pragma once
// A dataset of an HDF5 file as the raw bytes of its file type, for tests that compare files
// bit for bit; empty if the file or dataset cannot be read.

#include <hdf5.h>

#include <string>
#include <vector>

namespace cosserat::testing {

inline std::vector<unsigned char> dataset_bytes(const std::string& path, const char* name) {
  std::vector<unsigned char> bytes;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) return bytes;
  const hid_t dataset = H5Dopen2(file, name, H5P_DEFAULT);
  if (dataset >= 0) {
    const hid_t type = H5Dget_type(dataset);
    const hid_t space = H5Dget_space(dataset);
    bytes.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)) *
                 H5Tget_size(type));
    if (H5Dread(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data()) < 0) bytes.clear();
    H5Sclose(space);
    H5Tclose(type);
    H5Dclose(dataset);
  }
  H5Fclose(file);
  return bytes;
}

}  // namespace cosserat::testing
