# Every third-party dependency, each with the Debian package that provides it, so that a
# missing one stops configuration with a message saying what to install.
# setup.sh installs all of them; keep the two lists in step.

macro(terrain_require name debian_package)
  find_package(${name} ${ARGN} QUIET)
  if(NOT ${name}_FOUND)
    message(FATAL_ERROR
      "terrain needs ${name}, which was not found. On Debian/Ubuntu install it with:\n"
      "  apt-get install ${debian_package}\n"
      "(or run ./setup.sh, which installs every package the project needs)")
  endif()
endmacro()

terrain_require(GDAL libgdal-dev CONFIG)
terrain_require(PROJ libproj-dev CONFIG)
terrain_require(CGAL libcgal-dev CONFIG)
terrain_require(Boost libboost-program-options-dev 1.71 COMPONENTS program_options)
terrain_require(Eigen3 libeigen3-dev 3.3 NO_MODULE)
terrain_require(TBB libtbb-dev CONFIG)
terrain_require(Freetype libfreetype-dev)
set(MPI_CXX_SKIP_MPICXX ON)  # (the C API from C++: no deprecated C++ bindings)
terrain_require(MPI libopenmpi-dev COMPONENTS CXX)
find_package(Threads REQUIRED)

include(TerrainFindLibraries)
foreach(pair "terrain_geographiclib|GeographicLib|libgeographiclib-dev")
  string(REPLACE "|" ";" parts "${pair}")
  list(GET parts 0 target)
  list(GET parts 1 name)
  list(GET parts 2 package)
  if(NOT TARGET ${target})
    message(FATAL_ERROR
      "terrain needs ${name}, which was not found. On Debian/Ubuntu install it with:\n"
      "  apt-get install ${package}\n"
      "(or run ./setup.sh, which installs every package the project needs)")
  endif()
endforeach()

if(TERRAIN_BUILD_TESTS)
  terrain_require(Catch2 catch2 2.13 CONFIG)
endif()
