#pragma once
// A mover's configuration from Python keywords, shared by the serial and the distributed
// movers: each keyword's value becomes the option's text by the type the method describes,
// and the method's parser refuses a key it does not know, naming those it does. `other` takes
// the keys of options beside the method's (the distributed solves') first, when it knows them.

#include "bindings.hpp"

#include "meshmotion/movers/registry.hpp"

#include <functional>
#include <string>
#include <vector>

namespace meshmotion::python {

template <int Dim>
MoverConfig<Dim> mover_config_from(const std::string& method, const py::kwargs& options,
                                   const std::vector<OptionDoc>& other_docs = {},
                                   const std::function<bool(const std::string&, const std::string&)>& other = {}) {
  MoverConfig<Dim> config = mover_config<Dim>(method);
  std::vector<OptionDoc> docs = config.docs();
  docs.insert(docs.end(), other_docs.begin(), other_docs.end());
  for (const auto& [key, value] : options) {
    const std::string k = key.template cast<std::string>();
    const std::string text = option_text(docs, k, value);
    if (!other || !other(k, text)) config.set(k, text);
  }
  return config;
}

}  // namespace meshmotion::python
