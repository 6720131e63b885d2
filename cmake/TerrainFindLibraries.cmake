# Imported targets for libraries whose Debian CMake packages are missing or unusable:
# GeographicLib ships only a find module. Each target is found from its header and library,
# which is all terrain needs.

function(terrain_import_library target header library_names)
  if(TARGET ${target})
    return()
  endif()
  string(MAKE_C_IDENTIFIER "${target}" id)
  find_path(${id}_INCLUDE_DIR ${header})
  find_library(${id}_LIBRARY NAMES ${library_names})
  if(${id}_INCLUDE_DIR AND ${id}_LIBRARY)
    add_library(${target} UNKNOWN IMPORTED)
    set_target_properties(${target} PROPERTIES
      IMPORTED_LOCATION "${${id}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${${id}_INCLUDE_DIR}")
  endif()
endfunction()

terrain_import_library(terrain_geographiclib GeographicLib/Geocentric.hpp "GeographicLib;Geographic")
