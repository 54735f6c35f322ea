#include "cosserat/io/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "cosserat/grid/block.hpp"

namespace cosserat {
namespace {

enum Outcome : int { locked = 0, busy = 1, unopenable = 2 };

}  // namespace

// flock, not fcntl: an fcntl lock belongs to the process and goes away when it closes any
// descriptor of the file, which HDF5 and MPI-IO do on their own. HDF5's own file locking does
// not help: its MPI-IO driver takes no lock (HDF5 1.10.8, tried: a second run and h5py in
// append mode both open a file that a run is writing).
OutputLock::OutputLock(const std::string& path, MPI_Comm comm) {
  std::array<int, 3> outcome{locked, 0, 0};  // outcome, had contents, errno
  if (rank_in(comm) == 0) {
    descriptor_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    struct stat status {};
    if (descriptor_ < 0) {
      outcome = {unopenable, 0, errno};
    } else if (flock(descriptor_, LOCK_EX | LOCK_NB) != 0) {
      outcome = {errno == EWOULDBLOCK ? busy : unopenable, 0, errno};
    } else if (fstat(descriptor_, &status) != 0) {
      outcome = {unopenable, 0, errno};
    } else {
      outcome[1] = status.st_size > 0 ? 1 : 0;
    }
  }
  MPI_Bcast(outcome.data(), static_cast<int>(outcome.size()), MPI_INT, 0, comm);
  had_contents_ = outcome[1] != 0;
  if (outcome[0] == locked) return;
  if (descriptor_ >= 0) close(descriptor_);
  if (outcome[0] == busy)
    throw OutputBusy(fmt::format(
        "{} is locked by another process: another cosserat run is writing it (or a program is "
        "reading it through HDF5 with file locking on); wait for that run to end, or name "
        "another --output",
        path));
  throw std::runtime_error(
      fmt::format("cannot open {} to lock it: {}", path, std::strerror(outcome[2])));
}

OutputLock::~OutputLock() {
  if (descriptor_ >= 0) close(descriptor_);
}

}  // namespace cosserat
