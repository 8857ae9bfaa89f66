// SPDX-License-Identifier: MIT
// Plugin registry: stages (metric fields, geometries, fillers, writers, ...) are registered by
// name and chosen with the YAML `type:` key; an unknown name is a ConfigError listing the known.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "modules/base/error.h"

namespace plaf {
inline namespace pipeline {

template <class Signature>
class Registry;

template <class R, class... Args>
class Registry<R(Args...)> {
 public:
  using Factory = std::function<R(Args...)>;

  explicit Registry(std::string what) : what_(std::move(what)) {}

  // Registering a name twice is a programming error and throws.
  void add(const std::string& name, Factory factory) {
    if (!factories_.emplace(name, std::move(factory)).second)
      throw Error("plugin '" + name + "' is registered twice as a " + what_);
  }
  bool contains(const std::string& name) const { return factories_.count(name) > 0; }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& kv : factories_) out.push_back(kv.first);
    return out;
  }
  // Throws ConfigError "where: unknown <what> 'name' (known: ...)" unless name is registered.
  void require(const std::string& name, const std::string& where) const {
    if (contains(name)) return;
    std::string known;
    for (const auto& kv : factories_) known += (known.empty() ? "" : ", ") + kv.first;
    throw ConfigError(where + ": unknown " + what_ + " '" + name + "' (known: " + known + ")");
  }
  // where: "file:line:col: key" of the `type:` value, for the message.
  R create(const std::string& name, const std::string& where, Args... args) const {
    require(name, where);
    return factories_.find(name)->second(std::forward<Args>(args)...);
  }

 private:
  std::string what_;
  std::map<std::string, Factory> factories_;
};

}  // namespace pipeline
}  // namespace plaf
