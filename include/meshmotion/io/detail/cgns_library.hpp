#pragma once
/// \file
/// The CGNS library's functions, loaded on first use instead of linked. Debian's libcgns pulls
/// HDF5 and, through it, curl, TLS and Kerberos: 39 shared objects whose loading cost every
/// program ~17 ms at start (twice with the huge-page restart of core/process_memory.hpp),
/// whether or not it ever touches a .cgns file. CMake passes the library it found as
/// MESHMOTION_CGNS_LIBRARY; the declarations still come from cgnslib.h, so every call is
/// type-checked against the installed library.

#ifdef MESHMOTION_HAVE_CGNS

#include "meshmotion/core/error.hpp"

#include <cgnslib.h>
#include <dlfcn.h>

#include <string>

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
  X(cg_famname_read) X(cg_dataclass_write) X(cg_exponents_write) X(cg_ElementDataSize) X(cg_ElementTypeName)

namespace meshmotion::detail {

struct CgnsLibrary {
#define MESHMOTION_CGNS_MEMBER(name) decltype(&::name) name = nullptr;
  MESHMOTION_CGNS_FUNCTIONS(MESHMOTION_CGNS_MEMBER)
#undef MESHMOTION_CGNS_MEMBER
};

/// The loaded library (opened once, kept open for the life of the process). Throws IoError
/// naming the library when it cannot be loaded or lacks a function.
inline const CgnsLibrary& cgns_api() {
  static const CgnsLibrary library = [] {
    void* handle = dlopen(MESHMOTION_CGNS_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* reason = dlerror();
      throw IoError(std::string("cannot load the CGNS library " MESHMOTION_CGNS_LIBRARY " (") +
                    (reason != nullptr ? reason : "unknown reason") + "; is libcgns installed?)");
    }
    // HDF5 (loaded with libcgns) closes its open files at exit, and crashes there on a file
    // whose write failed (a full disk, a file size limit): the program would end with a
    // segmentation fault after reporting the error. Every file is closed by its owner
    // (CgnsFile), so HDF5's exit handler is declined, before HDF5's first use.
    if (auto* dont_atexit = reinterpret_cast<int (*)()>(dlsym(handle, "H5dont_atexit"))) dont_atexit();
    CgnsLibrary loaded;
#define MESHMOTION_CGNS_LOAD(name)                                                                  \
  loaded.name = reinterpret_cast<decltype(&::name)>(dlsym(handle, #name));                         \
  if (loaded.name == nullptr)                                                                       \
    throw IoError("the CGNS library " MESHMOTION_CGNS_LIBRARY " has no function " #name " (another version?)");
    MESHMOTION_CGNS_FUNCTIONS(MESHMOTION_CGNS_LOAD)
#undef MESHMOTION_CGNS_LOAD
    return loaded;
  }();
  return library;
}

}  // namespace meshmotion::detail

#undef MESHMOTION_CGNS_FUNCTIONS

#endif  // MESHMOTION_HAVE_CGNS
