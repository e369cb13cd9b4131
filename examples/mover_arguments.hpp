#pragma once
// Command-line options of the mover shared by move_mesh and curve_mesh. Every value reaches
// the mover's typed options through the library's one parser (MoverConfig::set): a key the
// method does not take, or a value its field cannot hold, is refused with the known keys.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/movers/mover_options.hpp"

#include <CLI/CLI.hpp>

#include <array>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion::examples {

struct MoverArguments {
  std::string method = "rbf";
  std::vector<std::string> options;  // KEY=VALUE
  std::string options_file;          // KEY=VALUE lines
  bool list_options = false;
  // Shorthands for the most used keys, kept as text so that numbers are read exactly.
  std::array<std::pair<const char*, std::optional<std::string>>, 10> shorthands{{
      {"kernel", {}},
      {"solver", {}},
      {"tolerance", {}},
      {"stiffening_exponent", {}},
      {"poisson_ratio", {}},
      {"youngs_modulus", {}},
      {"distance_exponent", {}},
      {"active_radius", {}},
      {"load_steps", {}},
      {"polynomial", {}},
  }};
};

inline void add_mover_options(CLI::App& app, MoverArguments& a, const std::string& extra_methods) {
  app.add_option("--method", a.method, "mover: " + extra_methods + "rbf, dgm, idgm, dgrbf, dgrbf2, spring, torsion, le, sle, nle")
      ->capture_default_str();
  app.add_option("--option", a.options,
                 "mover option KEY=VALUE (repeatable; --list-options shows the method's keys and defaults)");
  app.add_option("--options-file", a.options_file, "file of mover options, KEY=VALUE per line or space, # comments")
      ->check(CLI::ExistingFile);
  app.add_flag("--list-options", a.list_options, "print the options of --method with their defaults and exit");
  const std::array<const char*, 10> help{
      "rbf/dgrbf/dgrbf2: kernel (wendland2, wendland0/4/6, tps, gaussian, multiquadric, inverse_multiquadric)",
      "sparse solver: simplicial_ldlt | simplicial_llt | sparse_lu | cg_jacobi | cg_incomplete_cholesky | bicgstab",
      "iterative solvers: relative residual",
      "le/sle: chi of the Jacobian stiffening (J0/J)^chi (sle default 2.75, le 0)",
      "le/sle/nle: Poisson ratio in (-1, 0.5) (default 0.3)",
      "le/sle/nle: Young's modulus > 0 (default 1; scales K only)",
      "le/sle: psi of the wall-distance stiffening (default 0)",
      "le/sle: solve only within this distance of the moving walls (0: whole mesh)",
      "nle: load increments (default 1)",
      "rbf: add a linear polynomial (true/false)",
  };
  for (std::size_t k = 0; k < a.shorthands.size(); ++k) {
    std::string flag = std::string("--") + a.shorthands[k].first;
    for (char& c : flag)
      if (c == '_') c = '-';
    app.add_option(flag, a.shorthands[k].second, std::string(help[k]) + " (= --option " + a.shorthands[k].first + "=...)");
  }
}

/// The options given, in order: the file, the shorthands, then --option (later ones win).
inline KeyValues given_options(const MoverArguments& a) {
  KeyValues out;
  if (!a.options_file.empty()) {
    std::ifstream in(a.options_file);
    if (!in) throw IoError("cannot open options file " + a.options_file);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    try {
      out = parse_key_values(text);
    } catch (const InputError& e) {
      throw InputError(a.options_file + ": " + e.what());
    }
  }
  for (const auto& [key, value] : a.shorthands)
    if (value) out.emplace_back(key, *value);
  for (const auto& option : a.options) {
    const auto eq = option.find('=');
    if (eq == std::string::npos || eq == 0) throw InputError("--option: expected KEY=VALUE (got '" + option + "')");
    out.emplace_back(option.substr(0, eq), option.substr(eq + 1));
  }
  return out;
}

/// Prints "method: summary" and each key with its default; true when --list-options was given.
template <int Dim>
bool list_options(const MoverArguments& a) {
  if (!a.list_options) return false;
  const MoverConfig<Dim> c = mover_config<Dim>(a.method);
  std::cout << c.method << ": " << mover_method<Dim>(a.method).summary << "\n";
  for (const auto& line : c.describe()) std::cout << "  " << line << "\n";
  return true;
}

}  // namespace meshmotion::examples
