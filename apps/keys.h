// SPDX-License-Identifier: MIT
// The key reference: every key the configuration parsers accept (a run configuration's and a
// study file's), with its type, default, range or allowed words, the plugin types that read it
// and a line of description. It is taken from the parsers themselves: a minimal configuration per
// registered plugin type is parsed under ConfigNode's recording mode (modules/pipeline/config.h),
// which keeps what each getter was asked; only the descriptions are written by hand, in one table
// (apps/key_notes.cpp). `plaf keys [SECTION]` prints it; docs/config.md is its Markdown
// (`plaf keys --markdown > docs/config.md`), which a test holds equal to what the code prints.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace plaf {

struct KeyEntry {
  std::string document;     // "run" (a run configuration) or "study" (plaf compare-attenuation)
  std::string section;      // the top-level key it is under; "top" for a run's top-level values
  std::string path;         // "geometry.bodies[].file": list items as "[]"
  std::string type;         // "number", "word", "text or section", ...
  std::string fallback;     // the default as written in YAML; "—" when absent means none or off
  bool fallback_is_value = true;  // false: words of key_notes() ("required", "h0"), not a value
  std::string range;        // "[0, 1]", "1..100", "> 0", or the allowed words "sphere, box"
  std::string read_by;      // the plugin types (sections with `type:`) or dimensions reading it
  std::string description;  // from apps/key_notes.cpp
};

struct KeyReference {
  std::vector<KeyEntry> entries;      // by section, in the order of key_notes(); keys in parse order
  std::vector<std::string> sections;  // the sections of both documents, in that order
  // What keeps the reference from being complete and true (empty when it is): a registered type no
  // configuration selected, a key only ever tested for presence, a key without a description, ...
  std::vector<std::string> problems;
};

// A hand-written line per key, and where the recorded default says less than the truth (a
// default computed from other keys, a required key), the default as text.
struct KeyNote {
  const char* key;   // a run configuration's key path, or "study:" and a study file's key path
  const char* text;
  const char* fallback = nullptr;
  // The parser computes the default from other values (another key, the file's name): the value
  // recorded is one instance of it, so `fallback` may differ from it. Otherwise a `fallback` that
  // differs from a single recorded value is a problem of the reference.
  bool computed = false;
};
const std::vector<KeyNote>& key_notes();

// The reference, collected by parsing (the stage plugins must be registered: register_all_plugins).
KeyReference collect_key_reference();

// The reference as text for a terminal (one section, or all when section is empty; an unknown
// section throws ConfigError naming it and the known ones), and the whole of docs/config.md.
std::string key_reference_text(const KeyReference& reference, const std::string& section = "");
std::string key_reference_markdown(const KeyReference& reference);

// `plaf keys [SECTION] [--markdown]`: prints the reference (problems, if any, as warnings on
// stderr); an empty SECTION is unknown (ConfigError); returns 0.
int keys_command(const std::optional<std::string>& section, bool markdown);

// `plaf keys --probes` (for the reference's test, tests/apps/keys_test.cpp, not for users): every
// run configuration key read with a range or allowed words, each with the configurations of the
// collection that read it so, as YAML [{key, range ("words: a, b" for words), configs: [text]}],
// so the test can set the key inside and outside the range and check the parse accepts and
// refuses as the reference says.
std::string key_probes_yaml();

}  // namespace plaf
