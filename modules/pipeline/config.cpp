// SPDX-License-Identifier: MIT
// Strict YAML reading (see config.h). yaml-cpp exceptions are translated into ConfigError with
// the file, line and column from Node::Mark().
#include "modules/pipeline/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "modules/base/error.h"
#include "modules/pipeline/data_root.h"

namespace plaf {
inline namespace pipeline {

struct ConfigNode::State {
  std::string file;
  std::string path;  // dotted path of this map ("" at the top)
  YAML::Node node;
  YAML::Mark mark;
  std::set<std::string> asked;
  std::vector<std::shared_ptr<State>> children;
  std::shared_ptr<std::vector<KeyAsk>> recording;  // set when loaded under a KeyRecording
  std::set<std::string> tested;                     // keys whose presence was asked (has, is_map)
};

namespace {

std::string position(const std::string& file, const YAML::Mark& m) {
  std::ostringstream s;
  s << file;
  if (m.line >= 0) s << ':' << m.line + 1 << ':' << m.column + 1;
  return s.str();
}

std::string dotted(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

// Const lookup: yaml-cpp's non-const operator[] would insert the key into the map.
YAML::Node lookup(const YAML::Node& map, const std::string& key) {
  return map[key];
}

std::string format_double(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// ---- recording (KeyRecording) ----

thread_local std::shared_ptr<std::vector<KeyAsk>> active_recording;

// A number as one writes it in YAML: 6 significant digits, plain unless the exponent form is
// shorter by two or more, exponents without padding (0.25, 0.005, 500000 -> 5e5, 1e-9).
std::string yaml_number(double x) {
  char plain[40], sci[40];
  std::snprintf(plain, sizeof plain, "%.6g", x);
  std::snprintf(sci, sizeof sci, "%.5e", x);
  std::string out = sci;  // d.ddddde[+-]XX
  const std::size_t e = out.find('e');
  std::string mantissa = out.substr(0, e), exponent = out.substr(e + 1);
  if (mantissa.find('.') != std::string::npos) {
    mantissa.erase(mantissa.find_last_not_of('0') + 1);
    if (mantissa.back() == '.') mantissa.pop_back();
  }
  const bool negative = exponent[0] == '-';
  exponent = exponent.substr(1);
  exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
  std::string shortest = plain;
  if (shortest.find('e') != std::string::npos || exponent != "0") {
    const std::string e_form = mantissa + "e" + (negative ? "-" : "") + exponent;
    if (e_form.size() + 2 <= shortest.size() || shortest.find('e') != std::string::npos) shortest = e_form;
  }
  return shortest;
}

template <class T, class Format>
std::string yaml_list(const std::vector<T>& items, Format format) {
  std::string out;
  for (const T& x : items) out += (out.empty() ? "" : ", ") + format(x);
  return "[" + out + "]";
}

// A range as the reference and the messages write it: "[0, 1]", "(1, 10]"; an upper end at the
// largest double is no bound: "[lo, max]" reads ">= lo", "(lo, max]" "> lo".
std::string range_text(double lo, double hi, Bounds bounds) {
  const bool open_lo = bounds == Bounds::OpenLow || bounds == Bounds::Open;
  const bool open_hi = bounds == Bounds::OpenHigh || bounds == Bounds::Open;
  std::string out;
  if (hi >= std::numeric_limits<double>::max()) {
    out = open_lo ? "> " : ">= ";
    out += yaml_number(lo);
    return out;
  }
  out = open_lo ? "(" : "[";
  out += yaml_number(lo);
  out += ", ";
  out += yaml_number(hi);
  out += open_hi ? ")" : "]";
  return out;
}

bool in_range(double x, double lo, double hi, Bounds bounds) {
  const bool open_lo = bounds == Bounds::OpenLow || bounds == Bounds::Open;
  const bool open_hi = bounds == Bounds::OpenHigh || bounds == Bounds::Open;
  return (open_lo ? x > lo : x >= lo) && (open_hi ? x < hi : x <= hi);
}

// "bodies[2].file" -> "bodies[].file": a key of any item of a list.
std::string item_pattern(const std::string& path) {
  std::string out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    out += path[i];
    if (path[i] == '[')
      while (i + 1 < path.size() && path[i + 1] != ']') ++i;
  }
  return out;
}

}  // namespace

const char* kind_name(KeyAsk::Kind kind) {
  switch (kind) {
    case KeyAsk::Kind::Presence: return "any";
    case KeyAsk::Kind::Number: return "number";
    case KeyAsk::Kind::Integer: return "integer";
    case KeyAsk::Kind::Bool: return "bool";
    case KeyAsk::Kind::Text: return "text";
    case KeyAsk::Kind::Choice: return "word";
    case KeyAsk::Kind::WordList: return "list of words";
    case KeyAsk::Kind::NumberList: return "list of numbers";
    case KeyAsk::Kind::PointList: return "list of [x, y]";
    case KeyAsk::Kind::Path: return "path";
    case KeyAsk::Kind::Section: return "section";
    case KeyAsk::Kind::SectionList: return "list of sections";
    case KeyAsk::Kind::Raw: return "YAML, passed on";
  }
  return "?";
}

KeyRecording::KeyRecording() : asks_(std::make_shared<std::vector<KeyAsk>>()), previous_(active_recording) {
  active_recording = asks_;
}

KeyRecording::~KeyRecording() { active_recording = previous_; }

void ConfigNode::note(const std::string& key, KeyAsk::Kind kind, std::string fallback, std::string range,
                      std::vector<std::string> choices) const {
  if (!s_->recording) return;  // no recording: no bookkeeping
  if (kind == KeyAsk::Kind::Presence) s_->tested.insert(key);
  KeyAsk a;
  a.path = item_pattern(dotted(s_->path, key));
  a.kind = kind;
  a.fallback = std::move(fallback);
  a.range = std::move(range);
  a.choices = std::move(choices);
  a.after_presence_test = kind != KeyAsk::Kind::Presence && s_->tested.count(key) > 0;
  s_->recording->push_back(std::move(a));
}

ConfigNode::ConfigNode(std::shared_ptr<State> s) : s_(std::move(s)) {}
ConfigNode::~ConfigNode() = default;
ConfigNode::ConfigNode(const ConfigNode&) = default;
ConfigNode& ConfigNode::operator=(const ConfigNode&) = default;

namespace {

// yaml-cpp keeps both entries of a key given twice in one map and finds the first: the second
// would never be checked. Reject it, naming both places (maps in lists included). Every map or list
// is visited once, by its position in the text: an alias shares its anchor's node, so a file of
// nested aliases (a "billion laughs") stays linear instead of exponential.
void reject_duplicate_keys(const YAML::Node& n, const std::string& file, const std::string& path,
                           std::set<std::pair<int, int>>& visited) {
  if (!n.IsMap() && !n.IsSequence()) return;
  if (!visited.insert({n.Mark().line, n.Mark().column}).second) return;
  if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i)
      reject_duplicate_keys(n[i], file, path + "[" + std::to_string(i) + "]", visited);
    return;
  }
  std::map<std::string, YAML::Mark> seen;
  for (const auto& kv : n) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
    const std::string dotted_key = path.empty() ? key : path + "." + key;
    const auto [it, fresh] = seen.emplace(key, kv.first.Mark());
    if (!fresh)
      throw ConfigError(position(file, kv.first.Mark()) + ": " + dotted_key + ": the key is given twice (first at " +
                        position(file, it->second) + ")");
    reject_duplicate_keys(kv.second, file, dotted_key, visited);
  }
}

}  // namespace

ConfigNode ConfigNode::load_string(const std::string& text, const std::string& name) {
  auto s = std::make_shared<State>();
  s->file = name;
  s->recording = active_recording;
  try {
    // One document: a second one (after ---) would be dropped without a word.
    const std::vector<YAML::Node> documents = YAML::LoadAll(text);
    if (documents.size() > 1)
      throw ConfigError(position(name, documents[1].Mark()) + ": a second YAML document (after ---); a config is one document");
    s->node = documents.empty() ? YAML::Node() : documents.front();
  } catch (const YAML::Exception& e) {
    throw ConfigError(position(name, e.mark) + ": YAML syntax error: " + e.msg);
  }
  if (s->node.IsNull()) s->node = YAML::Node(YAML::NodeType::Map);
  if (!s->node.IsMap()) throw ConfigError(position(name, s->node.Mark()) + ": the top level must be a map of keys");
  std::set<std::pair<int, int>> visited;
  reject_duplicate_keys(s->node, name, "", visited);
  s->mark = s->node.Mark();
  return ConfigNode(s);
}

ConfigNode ConfigNode::load_file(const std::filesystem::path& path) {
  // A directory, a device (/dev/zero) or a FIFO is no config: reading one would give a default
  // run, never end, or block.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path.string() + (std::filesystem::exists(path, ec) ? ": not a regular file (a config is a YAML file)"
                                                                        : ": cannot open the config file"));
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the config file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return load_string(buffer.str(), path.string());
}

const std::string& ConfigNode::file() const {
  return s_->file;
}

std::string ConfigNode::where(const std::string& key) const {
  if (key.empty()) return position(s_->file, s_->mark) + ": " + (s_->path.empty() ? "(top level)" : s_->path);
  const YAML::Node n = lookup(s_->node, key);
  return position(s_->file, n.IsDefined() ? n.Mark() : s_->mark) + ": " + dotted(s_->path, key);
}

bool ConfigNode::has(const std::string& key) const {
  s_->asked.insert(key);
  note(key, KeyAsk::Kind::Presence);
  const YAML::Node n = lookup(s_->node, key);
  return n.IsDefined() && !n.IsNull();
}

bool ConfigNode::is_map(const std::string& key) const {
  s_->asked.insert(key);
  note(key, KeyAsk::Kind::Presence);
  return lookup(s_->node, key).IsMap();
}

const YAML::Node* ConfigNode::value(const std::string& key) const {
  s_->asked.insert(key);
  thread_local YAML::Node holder;
  const YAML::Node n = lookup(s_->node, key);
  if (!n.IsDefined() || n.IsNull()) return nullptr;  // an absent key gives an invalid node
  holder.reset(n);                                   // rebind (assignment would copy content)
  return &holder;
}

double ConfigNode::get_double(const std::string& key, double fallback) const {
  note(key, KeyAsk::Kind::Number, yaml_number(fallback));
  return number(key, fallback);
}

double ConfigNode::number(const std::string& key, double fallback) const {
  const YAML::Node* n = value(key);
  if (!n) return fallback;
  double x = 0;
  try {
    if (!n->IsScalar()) throw YAML::Exception(n->Mark(), "");
    x = n->as<double>();
  } catch (const YAML::Exception&) {
    throw ConfigError(where(key) + ": expected a number, got '" + (n->IsScalar() ? n->Scalar() : "a list or map") +
                      "'");
  }
  if (!std::isfinite(x)) throw ConfigError(where(key) + ": expected a finite number");
  return x;
}

double ConfigNode::get_positive(const std::string& key, double fallback) const {
  note(key, KeyAsk::Kind::Number, yaml_number(fallback), "> 0");
  const double x = number(key, fallback);
  if (!(x > 0)) throw ConfigError(where(key) + ": must be positive, got " + format_double(x));
  return x;
}

double ConfigNode::get_in_range(const std::string& key, double fallback, double lo, double hi, Bounds bounds) const {
  const std::string range = range_text(lo, hi, bounds);
  note(key, KeyAsk::Kind::Number, yaml_number(fallback), range);
  const double x = number(key, fallback);
  if (!in_range(x, lo, hi, bounds)) throw ConfigError(where(key) + ": " + format_double(x) + " is outside " + range);
  return x;
}

double ConfigNode::get_zero_or_in_range(const std::string& key, double fallback, double lo, double hi,
                                        Bounds bounds) const {
  const std::string range = "0 or " + range_text(lo, hi, bounds);
  note(key, KeyAsk::Kind::Number, yaml_number(fallback), range);
  const double x = number(key, fallback);
  if (x != 0 && !in_range(x, lo, hi, bounds))
    throw ConfigError(where(key) + ": " + format_double(x) + " is outside " + range);
  return x;
}

int ConfigNode::get_int(const std::string& key, int fallback, int lo, int hi) const {
  note(key, KeyAsk::Kind::Integer, std::to_string(fallback), std::to_string(lo) + ".." + std::to_string(hi));
  const YAML::Node* n = value(key);
  if (!n) return fallback;
  long long x = 0;
  try {
    if (!n->IsScalar()) throw YAML::Exception(n->Mark(), "");
    x = n->as<long long>();
  } catch (const YAML::Exception&) {
    throw ConfigError(where(key) + ": expected an integer, got '" + (n->IsScalar() ? n->Scalar() : "a list or map") +
                      "'");
  }
  if (x < lo || x > hi)
    throw ConfigError(where(key) + ": " + std::to_string(x) + " is outside " + std::to_string(lo) + ".." +
                      std::to_string(hi));
  return static_cast<int>(x);
}

bool ConfigNode::get_bool(const std::string& key, bool fallback) const {
  note(key, KeyAsk::Kind::Bool, fallback ? "true" : "false");
  const YAML::Node* n = value(key);
  if (!n) return fallback;
  try {
    if (!n->IsScalar()) throw YAML::Exception(n->Mark(), "");
    return n->as<bool>();
  } catch (const YAML::Exception&) {
    throw ConfigError(where(key) + ": expected true or false, got '" + (n->IsScalar() ? n->Scalar() : "a list or map") +
                      "'");
  }
}

std::string ConfigNode::get_string(const std::string& key, const std::string& fallback) const {
  note(key, KeyAsk::Kind::Text, fallback);
  return word(key, fallback);
}

std::string ConfigNode::word(const std::string& key, const std::string& fallback) const {
  const YAML::Node* n = value(key);
  if (!n) return fallback;
  if (!n->IsScalar()) throw ConfigError(where(key) + ": expected a word, got a list or map");
  return n->Scalar();
}

std::string ConfigNode::get_choice(const std::string& key, const std::string& fallback,
                                   const std::vector<std::string>& allowed) const {
  note(key, KeyAsk::Kind::Choice, fallback, "", allowed);
  const std::string v = word(key, fallback);
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end())
    throw ConfigError(where(key) + ": unknown value '" + v + "' (known: " + join(allowed) + ")");
  return v;
}

std::vector<std::string> ConfigNode::get_string_list(const std::string& key, const std::vector<std::string>& fallback,
                                                     const std::vector<std::string>& allowed) const {
  note(key, KeyAsk::Kind::WordList, yaml_list(fallback, [](const std::string& w) { return w; }), "", allowed);
  const YAML::Node* n = value(key);
  if (!n) return fallback;
  if (!n->IsSequence()) throw ConfigError(where(key) + ": expected a list like [a, b]");
  std::vector<std::string> out;
  for (const auto& item : *n) {
    if (!item.IsScalar()) throw ConfigError(where(key) + ": list items must be words");
    const std::string v = item.Scalar();
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), v) == allowed.end())
      throw ConfigError(position(s_->file, item.Mark()) + ": " + dotted(s_->path, key) + ": unknown value '" + v +
                        "' (known: " + join(allowed) + ")");
    out.push_back(v);
  }
  return out;
}

std::vector<double> ConfigNode::get_double_list(const std::string& key, const std::vector<double>& fallback, double lo,
                                                double hi, Bounds bounds) const {
  const std::string range = range_text(lo, hi, bounds);
  note(key, KeyAsk::Kind::NumberList, yaml_list(fallback, yaml_number), range);
  const std::vector<double> out = numbers(key, fallback);
  for (double x : out)
    if (!in_range(x, lo, hi, bounds))
      throw ConfigError(where(key) + ": " + format_double(x) + " is outside " + range);
  return out;
}

std::vector<double> ConfigNode::get_double_list(const std::string& key, const std::vector<double>& fallback) const {
  note(key, KeyAsk::Kind::NumberList, yaml_list(fallback, yaml_number));
  return numbers(key, fallback);
}

std::vector<double> ConfigNode::numbers(const std::string& key, const std::vector<double>& fallback) const {
  const YAML::Node* n = value(key);
  if (!n) return fallback;
  if (!n->IsSequence()) throw ConfigError(where(key) + ": expected a list of numbers like [1, 2]");
  std::vector<double> out;
  for (const auto& item : *n) {
    try {
      out.push_back(item.as<double>());
    } catch (const YAML::Exception&) {
      throw ConfigError(position(s_->file, item.Mark()) + ": " + dotted(s_->path, key) + ": expected a number");
    }
    if (!std::isfinite(out.back())) throw ConfigError(where(key) + ": expected finite numbers");
  }
  return out;
}

std::vector<std::array<double, 2>> ConfigNode::get_point_list(const std::string& key) const {
  note(key, KeyAsk::Kind::PointList, "[]");
  const YAML::Node* n = value(key);
  std::vector<std::array<double, 2>> out;
  if (!n) return out;
  const std::string what = dotted(s_->path, key) + ": expected a list of points like [[0.5, 0.1], [1, 0]]";
  if (!n->IsSequence()) throw ConfigError(position(s_->file, n->Mark()) + ": " + what);
  for (const auto& item : *n) {
    if (!item.IsSequence() || item.size() != 2) throw ConfigError(position(s_->file, item.Mark()) + ": " + what);
    try {
      out.push_back({item[0].as<double>(), item[1].as<double>()});
    } catch (const YAML::Exception&) {
      throw ConfigError(position(s_->file, item.Mark()) + ": " + what);
    }
    if (!std::isfinite(out.back()[0]) || !std::isfinite(out.back()[1]))
      throw ConfigError(position(s_->file, item.Mark()) + ": " + what);
  }
  return out;
}

ConfigNode ConfigNode::child(const std::string& key) const {
  s_->asked.insert(key);
  note(key, KeyAsk::Kind::Section);
  auto c = std::make_shared<State>();
  c->file = s_->file;
  c->recording = s_->recording;
  c->path = dotted(s_->path, key);
  const YAML::Node n = lookup(s_->node, key);
  if (!n.IsDefined() || n.IsNull()) {
    c->node = YAML::Node(YAML::NodeType::Map);
    c->mark = s_->mark;
  } else if (!n.IsMap()) {
    throw ConfigError(position(s_->file, n.Mark()) + ": " + c->path + ": expected a map of keys");
  } else {
    c->node = n;
    c->mark = n.Mark();
  }
  s_->children.push_back(c);
  return ConfigNode(c);
}

std::vector<ConfigNode> ConfigNode::child_list(const std::string& key) const {
  s_->asked.insert(key);
  note(key, KeyAsk::Kind::SectionList);
  std::vector<ConfigNode> out;
  const YAML::Node n = lookup(s_->node, key);
  if (!n.IsDefined() || n.IsNull()) return out;
  if (!n.IsSequence())
    throw ConfigError(position(s_->file, n.Mark()) + ": " + dotted(s_->path, key) + ": expected a list of maps");
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node item = n[i];
    auto c = std::make_shared<State>();
    c->file = s_->file;
    c->path = dotted(s_->path, key) + "[" + std::to_string(i) + "]";
    c->recording = s_->recording;
    if (!item.IsMap()) throw ConfigError(position(s_->file, item.Mark()) + ": " + c->path + ": expected a map of keys");
    c->node = item;
    c->mark = item.Mark();
    s_->children.push_back(c);
    out.push_back(ConfigNode(c));
  }
  return out;
}

std::string ConfigNode::get_path(const std::string& key, const std::string& fallback) const {
  note(key, KeyAsk::Kind::Path, fallback);
  const std::string v = word(key, fallback);
  if (v.empty()) return v;
  if (v.rfind(kDataPrefix, 0) == 0) return resolve_data_path(v, where(key));  // data_root.h
  const std::filesystem::path p(v);
  if (p.is_absolute()) return v;
  return (std::filesystem::path(s_->file).parent_path() / p).lexically_normal().string();
}

YAML::Node ConfigNode::raw(const std::string& key) const {
  s_->asked.insert(key);
  note(key, KeyAsk::Kind::Raw);
  return lookup(s_->node, key);
}

void ConfigNode::finish() const {
  for (const auto& kv : s_->node) {
    const std::string key = kv.first.Scalar();
    if (!s_->asked.count(key)) {
      std::vector<std::string> known(s_->asked.begin(), s_->asked.end());
      throw ConfigError(position(s_->file, kv.first.Mark()) + ": unknown key '" + dotted(s_->path, key) +
                        "' (known here: " + (known.empty() ? std::string("none") : join(known)) + ")");
    }
  }
  for (const auto& c : s_->children) ConfigNode(c).finish();
}

}  // namespace pipeline
}  // namespace plaf
