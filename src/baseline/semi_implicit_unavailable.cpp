// A build without PETSc: the scene loader refuses "semi-implicit" before a Simulation exists,
// so every scheme there is to build is an explicit one.

#include <stdexcept>

#include "cosserat/baseline/semi_implicit.hpp"

namespace cosserat {

std::unique_ptr<Scheme> any_scheme(const SchemeSetup& setup) { return explicit_scheme(setup); }

void add_petsc_options(const std::string& options) {
  if (!options.empty()) throw std::invalid_argument("this build has no PETSc to pass options to");
}
void finalize_petsc() {}

}  // namespace cosserat
