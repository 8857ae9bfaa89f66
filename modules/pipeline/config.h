// SPDX-License-Identifier: MIT
// Strict YAML reading on yaml-cpp: every value is read through a ConfigNode, which remembers the
// keys asked for; finish() rejects any key nobody asked for, and loading rejects a key given twice
// in one map (yaml-cpp would keep the first and never check the second). Every error is a ConfigError
// "file:line:column: key.path: reason" (lines and columns 1-based).
//
// Recording mode (KeyRecording): every getter already knows its key, its default and its range or
// allowed words; while a recording is on, each call is kept, so the keys a parser accepts can be
// listed from the parser itself (the key reference, `plaf keys`, apps/keys.h) instead of from a
// copy that would go stale.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace plaf {
inline namespace pipeline {

// One key a getter was asked for, with what the getter knows of it.
struct KeyAsk {
  enum class Kind {
    Presence,    // has() or is_map(): only whether it is given
    Number,      // get_double, get_positive, get_in_range
    Integer,     // get_int
    Bool,        // get_bool
    Text,        // get_string
    Choice,      // get_choice: one of `choices`
    WordList,    // get_string_list (from `choices` when given)
    NumberList,  // get_double_list
    PointList,   // get_point_list
    Path,        // get_path
    Section,     // child
    SectionList, // child_list
    Raw,         // raw: passed on unread
  };
  std::string path;  // dotted from the top, list items as "[]": "geometry.bodies[].file"
  Kind kind = Kind::Presence;
  std::string fallback;  // the default as written in YAML ("" when the getter has none)
  std::string range;     // "> 0", "[0, 1]", "1..100" ("" when any value of the kind is taken)
  std::vector<std::string> choices;
  // The key's presence was tested on its map before this read: it is read only when given (or
  // is required), so `fallback` is a placeholder, not a default.
  bool after_presence_test = false;
};

const char* kind_name(KeyAsk::Kind kind);  // "number", "list of sections", ...

// Which ends of a range lo..hi belong to it: [lo, hi], (lo, hi], [lo, hi), (lo, hi).
enum class Bounds { Closed, OpenLow, OpenHigh, Open };

// While an instance lives, every ConfigNode loaded on this thread records its getters' calls
// into it (and so do the nodes taken from it: child, child_list). Recordings nest; the inner one
// records until it ends. Parsing with a recording on behaves exactly as without.
class KeyRecording {
 public:
  KeyRecording();
  ~KeyRecording();
  KeyRecording(const KeyRecording&) = delete;
  KeyRecording& operator=(const KeyRecording&) = delete;
  const std::vector<KeyAsk>& asks() const { return *asks_; }

 private:
  std::shared_ptr<std::vector<KeyAsk>> asks_;
  std::shared_ptr<std::vector<KeyAsk>> previous_;
};

class ConfigNode {
 public:
  // Parses a YAML file whose top level is a map. Missing file: InputError; syntax: ConfigError.
  static ConfigNode load_file(const std::filesystem::path& path);
  static ConfigNode load_string(const std::string& text, const std::string& name = "<string>");
  ~ConfigNode();
  ConfigNode(const ConfigNode&);
  ConfigNode& operator=(const ConfigNode&);

  bool has(const std::string& key) const;
  // The key holds a map (a section), not a scalar or a list.
  bool is_map(const std::string& key) const;
  // Values with defaults used when the key is absent; a range's ends are in it unless `bounds`
  // says otherwise (hi at the largest double: no upper bound). A value outside is an error
  // "file:line:col: key: VALUE is outside RANGE".
  double get_double(const std::string& key, double fallback) const;
  double get_positive(const std::string& key, double fallback) const;  // > 0
  double get_in_range(const std::string& key, double fallback, double lo, double hi,
                      Bounds bounds = Bounds::Closed) const;
  // 0 (off) or a value in the range: "0 or (1, 100]".
  double get_zero_or_in_range(const std::string& key, double fallback, double lo, double hi,
                              Bounds bounds = Bounds::Closed) const;
  int get_int(const std::string& key, int fallback, int lo, int hi) const;
  bool get_bool(const std::string& key, bool fallback) const;
  std::string get_string(const std::string& key, const std::string& fallback) const;
  // One of the allowed words; anything else is an error listing them.
  std::string get_choice(const std::string& key, const std::string& fallback,
                         const std::vector<std::string>& allowed) const;
  std::vector<std::string> get_string_list(const std::string& key, const std::vector<std::string>& fallback,
                                           const std::vector<std::string>& allowed) const;
  std::vector<double> get_double_list(const std::string& key, const std::vector<double>& fallback) const;
  // Every item in the range (as get_in_range).
  std::vector<double> get_double_list(const std::string& key, const std::vector<double>& fallback, double lo,
                                      double hi, Bounds bounds = Bounds::Closed) const;
  // A list of points [[x, y], ...] (empty when absent).
  std::vector<std::array<double, 2>> get_point_list(const std::string& key) const;
  // A nested map (empty when absent: every key takes its default).
  ConfigNode child(const std::string& key) const;
  // A list of maps (empty when absent), e.g. `bodies: [{file: a.dat}, {file: b.dat}]`.
  std::vector<ConfigNode> child_list(const std::string& key) const;
  // A path value, resolved relative to the folder of the config file (absolute paths stay), or
  // "data:REL", a published file found in the data roots (data_root.h; MissingDataError if none has it).
  std::string get_path(const std::string& key, const std::string& fallback) const;

  // The raw YAML value of a key (marked as asked; undefined when absent), for a caller that
  // passes a whole section on, unread, to another configuration (the attenuation study's runs:
  // their own parse checks its keys).
  YAML::Node raw(const std::string& key) const;

  // Throws on the first key of this map or any child read through child() that was never asked for.
  void finish() const;

  // "file:line:col: path.key" of a key (or of this map when key is empty), for messages.
  std::string where(const std::string& key = "") const;
  const std::string& file() const;

 private:
  struct State;
  explicit ConfigNode(std::shared_ptr<State> s);
  std::shared_ptr<State> s_;
  const YAML::Node* value(const std::string& key) const;  // marks the key used; null if absent
  // The unrecorded readers behind the getters (a getter built on another records once).
  double number(const std::string& key, double fallback) const;
  std::string word(const std::string& key, const std::string& fallback) const;
  std::vector<double> numbers(const std::string& key, const std::vector<double>& fallback) const;
  // Records an ask of `key` when a recording was on at load time.
  void note(const std::string& key, KeyAsk::Kind kind, std::string fallback = "", std::string range = "",
            std::vector<std::string> choices = {}) const;
};

}  // namespace pipeline
}  // namespace plaf
