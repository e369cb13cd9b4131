#pragma once
/// \file
/// The CGNS library's functions, loaded on first use instead of linked
/// (core/detail/shared_library.hpp). Debian's libcgns pulls HDF5 and, through it, curl, TLS
/// and Kerberos: 39 shared objects whose loading cost every program ~17 ms at start (twice
/// with the huge-page restart of core/process_memory.hpp), whether or not it ever touches a
/// .cgns file. CMake passes the library it found as
/// MESHMOTION_CGNS_LIBRARY; the declarations still come from cgnslib.h, so every call is
/// type-checked against the installed library.

#ifdef MESHMOTION_HAVE_CGNS

#include "meshmotion/core/detail/shared_library.hpp"
#include "meshmotion/core/error.hpp"

#include <cgnslib.h>
#include <dlfcn.h>

#ifndef MESHMOTION_CGNS_LIBRARY
#define MESHMOTION_CGNS_LIBRARY "libcgns.so"
#endif

// Every function of the CGNS API that io/cgns.hpp calls.
#define MESHMOTION_CGNS_FUNCTIONS(X)                                                                          \
  X(cg_open) X(cg_close) X(cg_get_error) X(cg_goto) X(cg_nbases) X(cg_base_read) X(cg_base_write)            \
  X(cg_nzones) X(cg_zone_type) X(cg_zone_read) X(cg_zone_write) X(cg_ncoords) X(cg_coord_info)               \
  X(cg_coord_read) X(cg_coord_write) X(cg_nsections) X(cg_section_read) X(cg_elements_read)                  \
  X(cg_poly_elements_read) X(cg_section_write) X(cg_poly_section_write) X(cg_nbocos) X(cg_boco_info)         \
  X(cg_boco_read) X(cg_boco_write) X(cg_boco_gridlocation_read) X(cg_boco_gridlocation_write)                \
  X(cg_famname_read) X(cg_n1to1) X(cg_1to1_read) X(cg_dataclass_write) X(cg_exponents_write) X(cg_ElementDataSize) X(cg_ElementTypeName)

namespace meshmotion::detail {

struct CgnsLibrary {
  MESHMOTION_CGNS_FUNCTIONS(MESHMOTION_LIBRARY_MEMBER)
};

/// The loaded library (opened once, kept open for the life of the process). Throws IoError
/// naming the library when it cannot be loaded or lacks a function.
inline const CgnsLibrary& cgns_api() {
  return loaded_api<CgnsLibrary, IoError>(MESHMOTION_CGNS_LIBRARY, "CGNS", [](const LoadedLibrary<IoError>& library, CgnsLibrary& api) {
    // HDF5 (loaded with libcgns) closes its open files at exit, and crashes there on a file
    // whose write failed (a full disk, a file size limit): the program would end with a
    // segmentation fault after reporting the error. Every file is closed by its owner
    // (CgnsFile), so HDF5's exit handler is declined, before HDF5's first use.
    if (auto* dont_atexit = reinterpret_cast<int (*)()>(dlsym(library.handle(), "H5dont_atexit"))) dont_atexit();
    MESHMOTION_CGNS_FUNCTIONS(MESHMOTION_LIBRARY_LOAD)
  });
}

}  // namespace meshmotion::detail

#undef MESHMOTION_CGNS_FUNCTIONS

#endif  // MESHMOTION_HAVE_CGNS
