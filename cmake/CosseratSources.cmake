# The sources of the modules below io (docs/design.md, "Modules"), relative to src/<module>/,
# and the options some of them are compiled with: one list for the main build (CMakeLists.txt)
# and for the step loop under SimGrid's SMPI (benchmarks/smpi/CMakeLists.txt).
set(COSSERAT_GRID_SOURCES decomposition.cpp halo.cpp reduce.cpp threads.cpp)
set(COSSERAT_MODEL_SOURCES cosserat_energy.cpp cosserat_model.cpp surface_measures.cpp
  wave_speed.cpp model_spec.cpp force_model.cpp mass_spring.cpp)
set(COSSERAT_CONTACT_SOURCES contact.cpp self_contact.cpp geometry.cpp obj_mesh.cpp mesh_tree.cpp
  rotation.cpp)
set(COSSERAT_SCENE_SOURCES checked_toml.cpp overrides.cpp scene.cpp presets.cpp solids.cpp)
set(COSSERAT_TIME_SOURCES constraints.cpp dynamics.cpp scheme.cpp verlet_family.cpp
  velocity_schemes.cpp stepper.cpp edge_check.cpp failure_diagnosis.cpp simulation.cpp
  stability.cpp step_loop.cpp adaptive_step.cpp gust_field.cpp)

# Sets the per-file options on the sources under `root`/src, in the calling directory's scope.
function(cosserat_source_options root)
  # The energy kernel's square roots vectorise only without errno (never read in this code).
  # Its selections (a ? b : c, in the crushed cells' bound) vectorise for AVX2, which has no
  # masked arithmetic, only where the compiler may compute both arms: without
  # -ftrapping-math, which changes no result but lets an unselected arm raise a flag. A build
  # that traps those flags keeps it.
  set(selections -fno-trapping-math)
  if(COSSERAT_TRAP_FPE)
    set(selections)
  endif()
  set_source_files_properties(${root}/src/model/cosserat_energy.cpp
    PROPERTIES COMPILE_OPTIONS "-fno-math-errno;${selections}")
  # The same for the contact's plane lanes (their square roots and selections), and only
  # without the -frounding-math that CGAL's target adds to the module: no code of this file
  # changes the rounding mode, or calls CGAL.
  set_source_files_properties(${root}/src/contact/contact.cpp
    PROPERTIES COMPILE_OPTIONS "-fno-math-errno;-fno-rounding-math;${selections}")
endfunction()
