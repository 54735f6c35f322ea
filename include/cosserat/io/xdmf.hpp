#pragma once
// The XDMF 3 description of /positions that lets ParaView open the HDF5 output as a time series
// of structured surfaces (with its "Xdmf3 Reader S" or "T", the default for .xmf).

#include <string>
#include <vector>

namespace cosserat {

// Writes xmf_path describing frames 0 .. times.size() - 1 of /positions, an array
// [frames, m, n, 3] in h5_filename_relative (a path relative to the folder of xmf_path).
// The file is written beside its final name and renamed into place, so a reader sees either
// the previous version or the new one, never a partial file. Throws std::runtime_error.
void write_xdmf(const std::string& xmf_path, const std::string& h5_filename_relative, int m, int n,
                const std::vector<double>& times);

}  // namespace cosserat
