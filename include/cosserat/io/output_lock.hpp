#pragma once
// One writer per output file (issue 12, defect 4): two runs with the same --output would both
// write it and leave it unreadable. The output is locked (flock, exclusive, advisory) by rank 0
// from before anything is written until the run ends; the kernel drops the lock when the process
// ends, however it ends, so a killed run never leaves a stale lock behind (docs/output.md).

#include <mpi.h>

#include <stdexcept>
#include <string>

namespace cosserat {

// The output is locked by another process: a run writing it, or a program reading it through
// HDF5 with its file locking on. Nothing has been written.
class OutputBusy : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class OutputLock {
 public:
  // Collective over comm: rank 0 opens `path` (creating it, empty, if absent) and locks it
  // without waiting; every rank learns the outcome. Throws OutputBusy on every rank when another
  // process holds the lock, std::runtime_error when the file cannot be opened.
  OutputLock(const std::string& path, MPI_Comm comm);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  // Whether the output held something when it was locked, as rank 0 saw it: an empty file (left
  // by a run killed between taking the lock and creating the HDF5 file) counts as none.
  bool had_contents() const { return had_contents_; }

 private:
  int descriptor_ = -1;
  bool had_contents_ = false;
};

}  // namespace cosserat
