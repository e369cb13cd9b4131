#pragma once
// Command-line options generated from the library's option descriptions (visit_options): a
// flag per key, --key VALUE (a list: several values or commas; a bool: --key and --no-key),
// plus --option KEY=VALUE and --options-file for any key. Every value reaches the typed
// options through the library's one parser: a key the method does not take, or a value its
// field cannot hold, is refused with the known keys.

#include "meshmotion/core/option_text.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/movers/registry.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdint>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace meshmotion::examples {

struct MoverArguments {
  std::string method = "rbf";
  KeyValues given;           // the flags and --option, in command-line order
  std::string options_file;  // KEY=VALUE lines
  bool list_options = false;
};

/// "--support-radius" for "support_radius".
inline std::string flag_of(const std::string& key) {
  std::string flag = "--" + key;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

/// A flag per key of `docs` that `app` does not have yet; each flag given appends
/// (key, text) to `sink`, so that later flags win as the parser applies them in order.
inline void add_option_flags(CLI::App& app, const std::vector<OptionDoc>& docs, KeyValues& sink, const std::string& group) {
  for (const OptionDoc& d : docs) {
    const std::string flag = flag_of(d.key);
    if (app.get_option_no_throw(flag) != nullptr) continue;
    const std::string help = d.doc + " [" + d.type + "]";
    CLI::Option* option = nullptr;
    if (d.type == "bool") {
      option = app.add_flag_function(flag, [&sink, key = d.key](std::int64_t) { sink.emplace_back(key, "true"); }, help);
      const std::string negated = "--no-" + flag.substr(2);
      if (app.get_option_no_throw(negated) == nullptr)
        app.add_flag_function(negated, [&sink, key = d.key](std::int64_t) { sink.emplace_back(key, "false"); },
                              "= " + flag + " false")
            ->group(group);
    } else if (d.type == "names" || d.type == "integers" || d.type == "numbers" || d.type.ends_with(" numbers")) {
      option = app.add_option_function<std::vector<std::string>>(
          flag,
          [&sink, key = d.key](const std::vector<std::string>& items) {
            std::string joined;
            for (const auto& item : items) {
              if (!joined.empty()) joined += ',';
              joined += item;
            }
            sink.emplace_back(key, joined);
          },
          help);
    } else {
      option = app.add_option_function<std::string>(
          flag, [&sink, key = d.key](const std::string& text) { sink.emplace_back(key, text); }, help);
    }
    option->group(group);
  }
}

/// Every key of every registered method, once, its help naming the methods that take it.
template <int Dim>
std::vector<OptionDoc> every_mover_option() {
  std::vector<OptionDoc> out;
  std::vector<std::string> takers;
  for (const auto& m : mover_methods<Dim>())
    for (OptionDoc& d : mover_config<Dim>(std::string(m.name)).docs()) {
      const auto it = std::find_if(out.begin(), out.end(), [&](const OptionDoc& o) { return o.key == d.key; });
      if (it == out.end()) {
        out.push_back(std::move(d));
        takers.emplace_back(m.name);
      } else {
        takers[static_cast<std::size_t>(it - out.begin())] += ", " + std::string(m.name);
      }
    }
  for (std::size_t k = 0; k < out.size(); ++k) out[k].doc += " (" + takers[k] + ")";
  return out;
}

/// --method (unless `with_method` is false: the program has its own), --option,
/// --options-file, --list-options and a flag per mover key.
inline void add_mover_options(CLI::App& app, MoverArguments& a, const std::string& methods_help, bool with_method = true) {
  if (with_method) app.add_option("--method", a.method, "mover: " + methods_help)->capture_default_str();
  app.add_option_function<std::vector<std::string>>(
      "--option",
      [&a](const std::vector<std::string>& options) {
        for (const auto& option : options) {
          const auto eq = option.find('=');
          if (eq == std::string::npos || eq == 0) throw CLI::ValidationError("--option", "expected KEY=VALUE (got '" + option + "')");
          a.given.emplace_back(option.substr(0, eq), option.substr(eq + 1));
        }
      },
      "option KEY=VALUE (repeatable; --list-options shows the keys and defaults)");
  app.add_option("--options-file", a.options_file, "file of options, KEY=VALUE per line or space, # comments");
  app.add_flag("--list-options", a.list_options, "print the options of --method with their defaults and exit");
  add_option_flags(app, every_mover_option<3>(), a.given, "Mover options (--list-options: those of --method)");
}

/// The options given, in order: the file, then the flags and --option as given (later ones win).
inline KeyValues given_options(const MoverArguments& a) {
  KeyValues out;
  if (!a.options_file.empty()) {
    const std::string text = detail::read_whole_file(a.options_file);
    try {
      out = parse_key_values(text);
    } catch (const InputError& e) {
      throw InputError(a.options_file + ": " + e.what());
    }
  }
  out.insert(out.end(), a.given.begin(), a.given.end());
  return out;
}

/// Prints "title" and each key with its type, default and help.
inline void print_option_docs(const std::string& title, const std::vector<OptionDoc>& docs) {
  std::cout << title << "\n";
  for (const OptionDoc& d : docs)
    std::cout << "  " << d.key << " (" << d.type << ", " << (d.value.empty() ? "empty" : d.value) << "): " << d.doc << "\n";
}

/// Prints the method's summary and its keys with their defaults; true when --list-options was given.
template <int Dim>
bool list_options(const MoverArguments& a) {
  if (!a.list_options) return false;
  print_option_docs(a.method + ": " + std::string(mover_method<Dim>(a.method).summary), mover_config<Dim>(a.method).docs());
  return true;
}

}  // namespace meshmotion::examples
