#pragma once
// What every example program shares: --version, the checks made before any work (output
// format and folder, input never overwritten unasked), the orientation handling, and one way
// of reporting errors (a message on stderr, and with --json the same {"error": ...} object on
// stdout) with one set of exit codes.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/json.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/orientation.hpp"
#include "meshmotion/core/process_memory.hpp"
#include "meshmotion/core/threads.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/version.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <iostream>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#if defined(__unix__)
#include <sys/resource.h>
#endif

namespace meshmotion::examples {

// Exit codes of every program.
inline constexpr int exit_ok = 0;
inline constexpr int exit_error = 1;    // bad input, unreadable file, solver failure: nothing written
inline constexpr int exit_invalid = 2;  // invalid cells: written with them (the last line says so), or refused by --strict

inline void add_version_flag(CLI::App& app) { app.set_version_flag("--version", "meshmotion " MESHMOTION_VERSION_STRING); }

/// The error object every program prints on stdout under --json.
inline void print_error_json(std::string_view message, std::string_view kind, int exit_code) {
  JsonWriter w(std::cout);
  w.begin_object().key("error").value(message).key("kind").value(kind).key("exit_code").value(exit_code).end_object();
  std::cout << "\n";
}

/// What the program is doing now ("reading case.su2", "moving case.su2 with rbf"). An error
/// whose own message names nothing (running out of memory, an exception from outside the
/// library) is reported with it, so that a user knows which input and which stage failed.
inline std::string& current_stage() {
  static std::string stage;
  return stage;
}
inline void set_stage(std::string stage) { current_stage() = std::move(stage); }

/// "out of memory while moving case.su2 with rbf (peak resident memory 1.25 GB): ...".
[[nodiscard]] inline std::string out_of_memory_message() {
  // The stage's text is freed on unwinding: these few bytes are available again.
  std::string m = "out of memory";
  if (!current_stage().empty()) m += " while " + current_stage();
#if defined(__unix__)
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) == 0 && usage.ru_maxrss > 0) {
    char peak[64];
    std::snprintf(peak, sizeof peak, " (peak resident memory %.3g GB)", static_cast<double>(usage.ru_maxrss) / (1024.0 * 1024.0));
    m += peak;
  }
#endif
  return m + ": the case needs more than this process may allocate (see ulimit -v, or a larger machine)";
}

/// Parses the command line. --help and --version print and give exit 0; every other parse
/// error (an unknown option, a value out of range, a missing file) is an input error like any
/// other: exit 1, the message on stderr and, under --json, the error object on stdout. `print`
/// is false on the ranks of a parallel program that stay silent.
[[nodiscard]] inline std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv, bool print = true) {
  const auto refuse = [&](const char* what, std::string_view kind, std::string_view hint) {
    if (!print) return exit_error;
    // --json may come after the word that failed: look for it in the words themselves.
    if (std::any_of(argv + 1, argv + argc, [](const char* word) { return std::string_view(word) == "--json"; }))
      print_error_json(what, kind, exit_error);
    std::cerr << app.get_name() << ": " << what << "\n" << hint;
    return exit_error;
  };
  try {
    app.parse(argc, argv);
    check_thread_environment();
    return std::nullopt;
  } catch (const InputError& e) {
    return refuse(e.what(), "input", "");
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return print ? app.exit(e) : 0;
    return refuse(e.what(), "usage", "Run with --help for more information.\n");
  }
}

/// Runs body() (which returns the exit code) and turns what it throws into a message on
/// stderr (and the error object on stdout under --json) and an exit code.
template <class Body>
int guarded(bool json, Body&& body) {
  const auto fail = [&](const char* what, std::string_view kind, int code) {
    if (json) print_error_json(what, kind, code);
    std::cerr << what << "\n";
    return code;
  };
  try {
    return body();
  } catch (const InvalidMeshError& e) {
    return fail(e.what(), "invalid_mesh", exit_invalid);
  } catch (const ParseError& e) {
    return fail(e.what(), "parse", exit_error);
  } catch (const InputError& e) {
    return fail(e.what(), "input", exit_error);
  } catch (const IoError& e) {
    return fail(e.what(), "io", exit_error);
  } catch (const SolverError& e) {
    return fail(e.what(), "solver", exit_error);
  } catch (const Error& e) {
    return fail(e.what(), "error", exit_error);
  } catch (const std::bad_alloc&) {
    return fail(out_of_memory_message().c_str(), "memory", exit_error);
  } catch (const std::exception& e) {
    // Not one of the library's errors (a standard library length or range error): still one
    // message and the error object, never an abort.
    const std::string stage = current_stage().empty() ? "" : " while " + current_stage();
    const std::string what = "internal error" + stage + ": " + e.what();
    return fail(what.c_str(), "internal", exit_error);
  } catch (...) {
    return fail("internal error: an exception of unknown type", "internal", exit_error);
  }
}

/// A mesh of an OpenFOAM case chosen as OpenFOAM's tools choose it (-time, -latestTime, -region).
struct FoamSelection {
  std::string time{}, region{};
  bool latest_time = false;
};

inline void add_foam_options(CLI::App& app, FoamSelection& s) {
  app.add_option("--time", s.time, "OpenFOAM case: its mesh at this time (the points it moved to), as OpenFOAM's -time");
  app.add_flag("--latest-time", s.latest_time, "OpenFOAM case: its mesh at the latest time, as OpenFOAM's -latestTime");
  app.add_option("--region", s.region, "OpenFOAM case: this region's mesh (constant/REGION/polyMesh), as OpenFOAM's -region");
}

/// The folder that `s` selects in the OpenFOAM case `input` (`input` when nothing is
/// selected): a region's polyMesh folder, or a time folder (`case/0.3`, `case/0.3/REGION`).
/// InputError when `input` is no such case or holds no such time.
[[nodiscard]] inline std::filesystem::path foam_input(const std::filesystem::path& input, const FoamSelection& s) {
  if (s.time.empty() && !s.latest_time && s.region.empty()) return input;
  if (!s.time.empty() && s.latest_time) throw InputError("give --time or --latest-time, not both");
  const std::filesystem::path mesh = s.region.empty() ? input / "constant" / "polyMesh" : input / "constant" / s.region / "polyMesh";
  std::error_code ec;
  if (!std::filesystem::exists(mesh / "faces", ec) && !std::filesystem::exists(mesh / "faces.gz", ec))
    throw InputError(input.string() + ": --time, --latest-time and --region choose in an OpenFOAM case folder, and " + mesh.string() +
                     " holds no mesh");
  double wanted = 0;
  if (!s.time.empty() && !detail::is_foam_time_name(s.time, &wanted)) throw InputError("--time " + s.time + ": not a time");
  std::string time;
  double latest = -std::numeric_limits<double>::infinity();
  std::string times;
  for (const auto& entry : std::filesystem::directory_iterator(input, ec)) {
    const std::string name = entry.path().filename().string();
    double t = 0;
    if (!entry.is_directory(ec) || !detail::is_foam_time_name(name, &t)) continue;
    times += (times.empty() ? "" : ", ") + name;
    if ((s.latest_time && t > latest) || (!s.time.empty() && t == wanted)) {
      time = name;
      latest = t;
    }
  }
  if (!s.time.empty() && time.empty())
    throw InputError(input.string() + ": no time " + s.time + " (times: " + (times.empty() ? std::string("none") : times) + ")");
  if (time.empty()) return mesh;  // --latest-time in a case that has not run: its constant mesh
  if (s.region.empty()) return input / time;
  if (!std::filesystem::is_directory(input / time / s.region, ec))
    throw InputError(input.string() + ": time " + time + " has no folder for region " + s.region);
  return input / time / s.region;
}

/// Where the moved mesh of a selected region goes when `output` is its case or a time folder
/// of it: that region's mesh there. Any other output as given.
[[nodiscard]] inline std::filesystem::path foam_output(const std::filesystem::path& output, const FoamSelection& s) {
  if (s.region.empty()) return output;
  std::error_code ec;
  if (std::filesystem::is_directory(output / "constant" / s.region, ec)) return output / "constant" / s.region / "polyMesh";
  const std::filesystem::path folder = output.has_filename() ? output : output.parent_path();
  const std::filesystem::path case_dir = folder.parent_path().empty() ? std::filesystem::path(".") : folder.parent_path();
  if (detail::is_foam_time_name(folder.filename().string()) && std::filesystem::is_directory(case_dir / "constant" / s.region, ec))
    return folder / s.region;
  return output;
}

/// read_mesh() with the stage set.
[[nodiscard]] inline AnyMesh read_input(const std::filesystem::path& file) {
  set_stage("reading " + file.string());
  return read_mesh(file);
}

/// write_mesh() with the stage set; the moved mesh of an OpenFOAM case `input` is written as
/// that case moved (write_moved_case(): a new case keeps the input's cells, patches and zones).
template <int Dim>
void write_output(const std::filesystem::path& file, const Mesh<Dim>& mesh, const std::filesystem::path& input = {}) {
  set_stage("writing " + file.string());
  std::error_code ec;
  if constexpr (Dim == 3) {
    if (!input.empty() && std::filesystem::is_directory(input, ec) && (is_openfoam_target(file) || is_new_openfoam_case(file)))
      return write_moved_case(file, input, mesh);
  }
  write_mesh(file, mesh);
}

/// Refuses, before any work, an output the program could not write (unknown format, a format
/// without elements of `order`, a missing folder) and an output that is the input unless
/// `overwrite`.
inline void check_output(const std::filesystem::path& input, const std::filesystem::path& output, int order,
                         bool overwrite) {
  check_mesh_output(output, order);
  std::error_code ec;
  if (!overwrite && !input.empty() && std::filesystem::exists(output, ec) && std::filesystem::equivalent(input, output, ec))
    throw InputError("output " + output.string() + " is the input file (give --overwrite to replace it)");
  // An OpenFOAM output named otherwise (the case's polyMesh folder for the case) that would
  // replace the points the input was read from.
  if (!overwrite && !input.empty() && std::filesystem::is_directory(input, ec) && is_openfoam_target(output)) {
    const std::filesystem::path written = detail::foam_points_target(output).points, read = detail::foam_points_target(input).points;
    if (!read.empty() && std::filesystem::weakly_canonical(written, ec) == std::filesystem::weakly_canonical(read, ec))
      throw InputError("output " + output.string() + " replaces the input's points (" + read.string() + "; give --overwrite to replace them)");
  }
}

/// Refuses, before any work, a side output (a picture, a .vtu of values beside the mesh, a
/// rank's part) in a missing folder, one that would replace a file the run reads (`inputs`:
/// the mesh, a geometry or options file; by any path to it — --overwrite lets only the output
/// mesh replace its input), and one that is another output of the run (`outputs`), which the
/// later write would replace.
inline void check_side_output(const std::filesystem::path& output, std::initializer_list<std::filesystem::path> inputs,
                              std::initializer_list<std::filesystem::path> outputs = {}) {
  check_output_folder(output);
  std::error_code ec;
  if (std::filesystem::is_directory(output, ec)) throw InputError("output " + output.string() + " is a folder (expected a file name)");
  for (const auto& input : inputs)
    if (!input.empty() && std::filesystem::exists(output, ec) && std::filesystem::equivalent(input, output, ec))
      throw InputError("output " + output.string() + " is " + (input == output ? "an input" : "the input " + input.string()) +
                       " of this run: no output is written over an input");
  const std::filesystem::path at = std::filesystem::weakly_canonical(output, ec);
  for (const auto& other : outputs)
    if (!other.empty() && std::filesystem::weakly_canonical(other, ec) == at)
      throw InputError("output " + output.string() + " is also the output " + other.string() + " of this run");
}

/// A consistently reversed mesh (every cell negative: the file's convention) is mirrored and
/// the program says so on stderr; with `keep` it is refused instead. A mixed one is reported
/// as such: its negative cells count as invalid.
template <int Dim>
void handle_orientation(Mesh<Dim>& mesh, const std::filesystem::path& file, bool keep) {
  const OrientationReport r = orientation_report(mesh);
  if (r.orientation() == CellOrientation::reversed) {
    if (keep)
      throw InputError(file.string() + ": every cell is negatively oriented (the file's convention is reversed; "
                       "without --keep-orientation the program reorients them)");
    const Index reoriented = fix_orientation(mesh);
    std::cerr << "note: " << file.string() << " lists every cell negatively oriented (reversed convention): reoriented "
              << reoriented << " of " << r.num_cells << " cells\n";
  } else if (r.orientation() == CellOrientation::mixed) {
    std::cerr << "warning: " << file.string() << " has mixed orientation: " << r.num_negative << " of " << r.num_cells
              << " cells are negative (inverted, or listed in the opposite order); they count as invalid\n";
  }
}

}  // namespace meshmotion::examples
