#pragma once
/// \file
/// A shared library opened on first use instead of linked: for the optional libraries whose
/// loading would cost every program at start what only some runs need (CGNS and its HDF5,
/// CHOLMOD and its BLAS). The declarations still come from the library's own headers, so that
/// every call is type-checked against the installed version.
///
/// \code
/// #define MY_FUNCTIONS(X) X(lib_open) X(lib_close)
/// struct MyApi { MY_FUNCTIONS(MESHMOTION_LIBRARY_MEMBER) };
/// const MyApi& api = loaded_api<MyApi, IoError>(MY_LIBRARY_PATH, "MyLib",
///     [](const LoadedLibrary<IoError>& library, MyApi& api) { MY_FUNCTIONS(MESHMOTION_LIBRARY_LOAD) });
/// \endcode

#include <dlfcn.h>

#include <string>
#include <string_view>

/// A member of an API struct for the library function `name`, typed by its declaration.
#define MESHMOTION_LIBRARY_MEMBER(name) decltype(&::name) name = nullptr;
/// Sets the member `name` of `api` from `library` (names as in loaded_api's callback).
#define MESHMOTION_LIBRARY_LOAD(name) library.load(api.name, #name);

namespace meshmotion::detail {

/// An opened library. Its handle is never closed: the library stays for the life of the
/// process. Failures throw E.
template <class E>
class LoadedLibrary {
 public:
  /// dlopen() of `path` (the file CMake found), else of its file name alone, which the loader
  /// looks for along LD_LIBRARY_PATH (programs moved with their libraries to another machine).
  /// Throws E naming `what` and the loader's reason when both fail.
  LoadedLibrary(const char* path, const std::string& what) : path_(path) {
    handle_ = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    const std::string_view full(path);
    if (const auto slash = full.rfind('/'); handle_ == nullptr && slash != std::string_view::npos)
      handle_ = dlopen(std::string(full.substr(slash + 1)).c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle_ == nullptr) {
      const char* reason = dlerror();
      throw E("cannot load the " + what + " library " + path_ + " (" + (reason != nullptr ? reason : "unknown reason") +
              "; is " + what + " installed?)");
    }
  }

  /// Sets `f` to the library's function `name`; throws E when it has none.
  template <class F>
  void load(F*& f, const char* name) const {
    f = reinterpret_cast<F*>(dlsym(handle_, name));
    if (f == nullptr) throw E("the library " + path_ + " has no function " + name + " (another version?)");
  }
  [[nodiscard]] void* handle() const noexcept { return handle_; }

 private:
  std::string path_;
  void* handle_ = nullptr;
};

/// The API struct Api of the library at `path`, filled once by `fill(library, api)`; throws E
/// when the library cannot be loaded or lacks a function (and tries again at the next call).
template <class Api, class E, class Fill>
[[nodiscard]] const Api& loaded_api(const char* path, const char* what, Fill&& fill) {
  static const Api api = [&] {
    const LoadedLibrary<E> library(path, what);
    Api loaded;
    fill(library, loaded);
    return loaded;
  }();
  return api;
}

}  // namespace meshmotion::detail
