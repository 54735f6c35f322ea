# Finds PETSc through pkg-config (Debian: libpetsc-real-dev) and provides the imported target
# PETSc::PETSc. Sets PETSc_FOUND and PETSc_VERSION. As preCICE's module, without its legacy
# PETSC_DIR/PETSC_ARCH probing: a package manager's PETSc ships a PETSc.pc, and a PETSc built
# by hand can be found by putting its lib/pkgconfig on PKG_CONFIG_PATH.

find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(_petsc QUIET PETSc)
  if(NOT _petsc_FOUND)
    pkg_check_modules(_petsc QUIET petsc)
  endif()
endif()

set(PETSc_VERSION "${_petsc_VERSION}")
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(PETSc
  REQUIRED_VARS _petsc_LINK_LIBRARIES _petsc_INCLUDE_DIRS
  VERSION_VAR PETSc_VERSION)

if(PETSc_FOUND AND NOT TARGET PETSc::PETSc)
  add_library(PETSc::PETSc INTERFACE IMPORTED)
  set_target_properties(PETSc::PETSc PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${_petsc_INCLUDE_DIRS}"
    INTERFACE_LINK_LIBRARIES "${_petsc_LINK_LIBRARIES}")
endif()
mark_as_advanced(PETSc_VERSION)
