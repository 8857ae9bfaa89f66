// SPDX-License-Identifier: MIT
// The key reference (keys.h), collected from the parsers under ConfigNode's recording mode.
//
// How completeness is ensured. A key is in the reference when some parse asked for it, so every
// place where a parser asks for a key only under a condition must be driven:
//   1. every registered type of every stage kind, in each dimension it is registered for, is
//      selected by a minimal configuration (type_seeds; the 2D surface types are chosen by the
//      geometry); a registered type that no configuration selected is a problem (below);
//   2. every word choice and every true/false key is tried with each of its other values, one at
//      a time on the configuration where it was asked (explore()); a variant that reaches keys not
//      seen before is explored in turn, so a choice that opens keys is followed to the end (none
//      does today beyond the types), and a default that depends on another key's value shows as
//      several defaults (isotropic_stop's on stop_when_linear), which a note must then state;
//   3. the places that open keys by the shape of a value rather than by a word are listed by hand
//      in shape_seeds, each with the reason: a key tested with has() or is_map() first (a circle
//      body, naca as a word or a map, output.cut, extrude, metric.intersect, a surface's
//      curvature_h_min) and a list whose items hold keys (bodies, symmetry_planes, zooms, cuts);
//      the checks below find one that is missing: a key only ever tested for presence, a list
//      whose items were never given, a key reached only by configurations that fail to parse.
// Any problem is printed by `plaf keys` as a warning and fails the key reference's test, as does a
// key without a description (apps/key_notes.cpp) or a description of no key.
#include "apps/keys.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <deque>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

#include "apps/run.h"
#include "apps/study.h"
#include "modules/base/error.h"
#include "modules/pipeline/config.h"
#include "modules/pipeline/run_config.h"
#include "modules/pipeline/stages.h"

namespace plaf {

namespace {

// ---- the configurations parsed -----------------------------------------------------------------

// One minimal section per registered plugin type: it selects the type and gives only what the
// type requires, so every default recorded is the type's own. dim 0: the type in both dimensions.
struct TypeSeed {
  StageKind kind;
  int dim;
  const char* type;
  const char* section;
};
const TypeSeed type_seeds[] = {
    {StageKind::Geometry, 2, "annulus", "{type: annulus}"},
    {StageKind::Geometry, 2, "airfoils", "{type: airfoils, bodies: [{file: section.dat}]}"},
    {StageKind::Geometry, 3, "sphere", "{type: sphere}"},
    {StageKind::Geometry, 3, "ellipsoid", "{type: ellipsoid}"},
    {StageKind::Geometry, 3, "box", "{type: box}"},
    {StageKind::Geometry, 3, "wing", "{type: wing, naca: '0012'}"},
    {StageKind::Geometry, 3, "surface_file", "{type: surface_file, file: body.stl}"},
    {StageKind::Metric, 0, "uniform", "{type: uniform}"},
    {StageKind::Metric, 0, "wall_power_law", "{type: wall_power_law}"},
    {StageKind::Metric, 0, "background", "{type: background, file: background.msh}"},
    {StageKind::Surface, 3, "remesh", "{type: remesh}"},
    {StageKind::Layers, 0, "none", "{type: none}"},
    {StageKind::Layers, 0, "extrude", "{type: extrude}"},
    {StageKind::Fill, 0, "none", "{type: none}"},
    {StageKind::Fill, 2, "advancing_front", "{type: advancing_front}"},
    {StageKind::Fill, 3, "tetgen", "{type: tetgen}"},
};

// The configuration a type's section is put into: the simplest body of the dimension; a 3D fill
// also needs layers (run_config.cpp refuses a TetGen fill without them).
std::string base_config(int dim, StageKind kind) {
  if (dim == 2) return "geometry: {type: airfoils, bodies: [{file: section.dat}]}\n";
  return std::string("geometry: {type: sphere}\n") + (kind == StageKind::Fill ? "layers: {type: extrude}\n" : "");
}

// The places that open keys by the shape of a value (point 3 above), each driven once.
struct ShapeSeed {
  const char* why;
  const char* config;
};
const ShapeSeed shape_seeds[] = {
    {"a body is a NACA section as a map or a word, or a circle (has: naca, circle; is_map: naca)",
     "geometry: {type: airfoils, bodies: [{naca: {digits: '0012'}}, {naca: '0012'}, {circle: {radius: 1}}]}\n"},
    {"a wing's section from a file instead of naca (has: naca)",
     "geometry: {type: wing, file: section.dat}\n"},
    {"a wing's NACA section as a map (is_map: naca)", "geometry: {type: wing, naca: {digits: '0012'}}\n"},
    {"a surface file's symmetry planes (list items)",
     "geometry: {type: surface_file, file: body.stl, symmetry_planes: [{normal: [0, 0, 1]}]}\n"},
    {"a 2D section extruded (has: extrude, hz)",
     "geometry: {type: airfoils, bodies: [{file: section.dat}]}\nextrude: {span: 1, hz: 0.1}\nlayers: {}\n"},
    {"curvature sizes' smallest size (has: curvature_h_min)",
     "geometry: {type: sphere}\nsurface: {curvature_factor: 1, curvature_h_min: 0.01}\n"},
    {"the 3D picture's cut and cuts (has: cut; list items)",
     "geometry: {type: sphere}\noutput: {cut: {point: [0, 0, 0], normal: [0, 0, 1]}, "
     "cuts: [{point: [0, 0, 0], normal: [1, 0, 0]}], zooms: [{box: [0, 1, 0, 1]}]}\n"},
    {"the 2D picture's zooms (list items)",
     "geometry: {type: annulus}\noutput: {zooms: [{box: [0, 1, 0, 1]}]}\n"},
};

// metric.intersect (has: intersect): a metric of each type with an item of the same type, in each
// dimension (made from the metric's type seeds in run_seeds()).

// A study with both partners: an extruded section, and a circle with its sphere and zooms (has:
// extrude, output, zooms).
const char* study_seed =
    "cases:\n"
    "  - {name: section, geometry: {type: airfoils, bodies: [{file: section.dat}]}, metric: {type: wall_power_law},\n"
    "     layers: {}, extrude: {span: 1}}\n"
    "  - {name: circle, geometry: {type: airfoils, bodies: [{circle: {radius: 1}}]}, metric: {type: wall_power_law},\n"
    "     layers: {}, sphere: true, output: {zooms: []}}\n";

struct Seed {
  std::string label;
  std::string text;
};

std::string emit(const YAML::Node& n) {
  YAML::Emitter e;
  e << n;
  return std::string(e.c_str()) + "\n";
}

std::vector<Seed> run_seeds() {
  std::vector<Seed> out;
  for (const TypeSeed& t : type_seeds)
    for (int dim : {2, 3}) {
      if (t.dim != 0 && t.dim != dim) continue;
      YAML::Node c = YAML::Load(base_config(dim, t.kind));
      c[stage_kind_name(t.kind)] = YAML::Load(t.section);
      out.push_back({std::string(stage_kind_name(t.kind)) + " " + t.type + " (" + std::to_string(dim) + "D)", emit(c)});
      if (t.kind == StageKind::Metric) {  // a metric of the type intersected with one of the same type
        YAML::Node i = YAML::Load(base_config(dim, t.kind));
        i["metric"] = YAML::Load(t.section);
        i["metric"]["intersect"].push_back(YAML::Load(t.section));
        out.push_back({std::string("metric.intersect ") + t.type + " (" + std::to_string(dim) + "D)", emit(i)});
      }
    }
  for (const ShapeSeed& s : shape_seeds) out.push_back({s.why, s.config});
  return out;
}

// ---- one parse under a recording ---------------------------------------------------------------

// Who read a key: the type of its section (empty for a section without `type:`) and the dimension
// of the section's stage (0 for a study file).
struct Context {
  std::string type;
  int dim = 0;
  bool operator<(const Context& o) const { return std::tie(type, dim) < std::tie(o.type, o.dim); }
};

struct Parse {
  std::string text;  // the configuration parsed
  bool ok = false;
  std::string error;
  std::vector<KeyAsk> asks;
  std::vector<Context> contexts;  // one per ask (ok only)
};

std::string top_of(const std::string& path) { return path.substr(0, path.find_first_of(".[")); }

Context run_context(const std::string& path, const RunConfig& r, const YAML::Node& yaml) {
  const std::string top = top_of(path);
  const int section_dim = r.extrude ? 2 : r.dim;  // an extruded run's section stages are 2D
  if (top == "geometry") return {r.geometry.type, section_dim};
  if (top == "metric") {
    if (path.rfind("metric.intersect[].", 0) == 0) return {yaml["metric"]["intersect"][0]["type"].as<std::string>(""), section_dim};
    return {r.metric.type, section_dim};
  }
  if (top == "surface") return {r.surface.type, section_dim};
  if (top == "layers") return {r.layers.type, r.dim};
  if (top == "fill") return {r.fill.type, r.dim};
  return {"", r.dim};
}

// A document kind's parse of a configuration's text under a recording.
using Parser = std::function<Parse(const std::string& text)>;

// A run configuration's; `types` collects the stage types it selected (kind, type, dimension), for
// point 1's check.
Parse parse_run(const std::string& text, std::set<std::tuple<std::string, std::string, int>>& types) {
  Parse p;
  KeyRecording recording;
  try {
    const RunConfig r = parse_run_config(text, "config.yaml");
    const YAML::Node yaml = YAML::Load(text);
    p.ok = true;
    p.asks = recording.asks();  // the asks and their contexts from one copy
    for (const KeyAsk& a : p.asks) p.contexts.push_back(run_context(a.path, r, yaml));
    const int section_dim = r.extrude ? 2 : r.dim;
    types.insert({"geometry", r.geometry.type, section_dim});
    types.insert({"metric", r.metric.type, section_dim});
    types.insert({"surface", r.surface.type, section_dim});
    types.insert({"layers", r.layers.type, r.dim});
    types.insert({"fill", r.fill.type, r.dim});
  } catch (const Error& e) {
    p.error = e.what();
    p.asks = recording.asks();
  }
  return p;
}

Parse parse_study(const std::string& text) {
  Parse p;
  KeyRecording recording;
  try {
    check_study(text, "study.yaml");
    p.ok = true;
    p.asks = recording.asks();  // the asks and their contexts from one copy
    p.contexts.assign(p.asks.size(), Context{});
  } catch (const Error& e) {
    p.error = e.what();
    p.asks = recording.asks();
  }
  return p;
}

// ---- exploring the choices (point 2) -----------------------------------------------------------

// text with the key at path ("a.b[].c": in the first item of list b) set to value; nothing when
// the way there is not a map (a key asked in a map given in another shape elsewhere).
std::optional<std::string> with_value(const std::string& text, const std::string& path, const std::string& value) {
  YAML::Node root = YAML::Load(text);
  YAML::Node cur = root;
  std::stringstream parts(path);
  std::string part;
  std::vector<std::string> names;
  while (std::getline(parts, part, '.')) names.push_back(part);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const bool item = names[i].size() > 2 && names[i].compare(names[i].size() - 2, 2, "[]") == 0;
    const std::string name = item ? names[i].substr(0, names[i].size() - 2) : names[i];
    if (!cur.IsMap()) return std::nullopt;
    if (i + 1 == names.size()) {
      cur[name] = value;
      break;
    }
    if (!cur[name].IsDefined() || cur[name].IsNull()) {
      if (item) return std::nullopt;
      cur[name] = YAML::Node(YAML::NodeType::Map);
    }
    YAML::Node next = cur[name];
    if (item) {
      if (!next.IsSequence() || next.size() == 0) return std::nullopt;
      next.reset(next[0]);
    }
    cur.reset(next);
  }
  return emit(root);
}

// Every value a choice or a true/false key may take.
std::vector<std::string> values_of(const KeyAsk& a) {
  if (a.kind == KeyAsk::Kind::Bool) return {"true", "false"};
  if (a.kind == KeyAsk::Kind::Choice) return a.choices;
  return {};
}

bool is_type_key(const std::string& path) { return path == "type" || (path.size() > 5 && path.rfind(".type") == path.size() - 5); }

struct Explored {
  std::vector<Parse> parses;  // every configuration parsed, seeds first
  std::vector<std::string> problems;
};

// Parses the seeds, then each choice and true/false key of a parse at its other values, one at a
// time; a variant that reaches new keys is explored in turn. Types are set by the seeds, not here.
Explored explore(const std::vector<Seed>& seeds, const Parser& parse) {
  Explored out;
  std::set<std::string> done, seen_paths;
  struct Item {
    std::string label, text;
    bool seed;
  };
  std::deque<Item> queue;
  for (const Seed& s : seeds) queue.push_back({s.label, s.text, true});
  while (!queue.empty()) {
    const Item item = queue.front();
    queue.pop_front();
    if (!done.insert(item.text).second) continue;
    Parse p = parse(item.text);
    p.text = item.text;
    if (!p.ok) {
      if (item.seed) out.problems.push_back("the configuration for " + item.label + " does not parse: " + p.error);
      out.parses.push_back(std::move(p));
      continue;
    }
    bool fresh = item.seed;
    for (const KeyAsk& a : p.asks) fresh = seen_paths.insert(a.path).second || fresh;
    if (fresh)
      for (const KeyAsk& a : p.asks) {
        if (is_type_key(a.path)) continue;
        for (const std::string& v : values_of(a))
          if (const auto variant = with_value(item.text, a.path, v))
            queue.push_back({item.label + ", " + a.path + ": " + v, *variant, false});
      }
    out.parses.push_back(std::move(p));
  }
  return out;
}

// ---- from the asks to the entries --------------------------------------------------------------

// Keys under `from` share the description of the key under `to` with the same rest: an
// intersected metric's keys are a metric section's, a body's NACA section is a wing's.
const std::pair<const char*, const char*> note_aliases[] = {
    {"metric.intersect[].", "metric."},
    {"geometry.bodies[].naca", "geometry.naca"},
};

struct Gathered {
  std::vector<KeyAsk::Kind> kinds;                      // typed reads, in order of appearance
  std::map<int, std::set<std::string>> fallbacks;       // by dimension, from reads not after has()
  std::map<std::string, std::set<std::string>> ranges;  // range -> types asking it
  std::vector<std::string> choices;
  std::set<Context> readers;  // typed reads only (a key tested and refused is not read)
  bool in_good_parse = false;
  std::size_t order = 0;
};

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

const StageKind* kind_of_section(const std::string& top) {
  for (const StageKind& k : all_stage_kinds)
    if (top == stage_kind_name(k)) return &k;
  return nullptr;
}

std::vector<std::pair<std::string, int>> registered(StageKind k) {
  std::vector<std::pair<std::string, int>> out;
  for (const std::string& n : stage_registry<2>(k).names()) out.push_back({n, 2});
  for (const std::string& n : stage_registry<3>(k).names()) out.push_back({n, 3});
  return out;
}

// "all types", "extrude (3D)", "uniform, background", "2D and 3D", "3D", ...
std::string readers_text(const std::string& document, const std::string& path, const std::set<Context>& readers) {
  if (document == "study") return "compare-attenuation";
  const StageKind* kind = kind_of_section(top_of(path));
  std::set<int> dims;
  for (const Context& c : readers) dims.insert(c.dim);
  if (!kind) return dims.size() == 2 ? "2D and 3D" : dims.count(3) ? "3D" : "2D";
  const auto all = registered(*kind);
  if (std::all_of(all.begin(), all.end(), [&](const auto& t) { return readers.count({t.first, t.second}) > 0; }))
    return "all types";
  std::vector<std::string> out;
  std::set<std::string> listed;
  for (const auto& [type, dim] : all) {
    (void)dim;
    if (listed.count(type)) continue;
    std::set<int> in_registry, reading;
    for (const auto& t : all)
      if (t.first == type) in_registry.insert(t.second);
    for (const Context& c : readers)
      if (c.type == type) reading.insert(c.dim);
    if (reading.empty()) continue;
    listed.insert(type);
    out.push_back(reading == in_registry ? type : type + (reading.count(2) ? " (2D)" : " (3D)"));
  }
  return join(out, ", ");
}

// The section a key is listed under: its top-level key, or "top" for a run's top-level values.
std::string section_of(const std::string& document, const std::string& path, const std::set<std::string>& maps) {
  if (document == "study") return "study";
  const std::string top = top_of(path);
  return maps.count(top) ? top : "top";
}

void add_entries(const std::string& document, const Explored& ex, KeyReference& ref) {
  std::map<std::string, Gathered> keys;
  std::size_t order = 0;
  for (const Parse& p : ex.parses)
    for (std::size_t i = 0; i < p.asks.size(); ++i) {
      const KeyAsk& a = p.asks[i];
      Gathered& g = keys[a.path];
      if (g.order == 0) g.order = ++order;
      if (!p.ok) continue;
      g.in_good_parse = true;
      if (a.kind == KeyAsk::Kind::Presence) continue;
      const Context& c = p.contexts[i];
      g.readers.insert(c);
      if (std::find(g.kinds.begin(), g.kinds.end(), a.kind) == g.kinds.end()) g.kinds.push_back(a.kind);
      if (!a.after_presence_test) g.fallbacks[c.dim].insert(a.fallback);
      if (!a.range.empty()) g.ranges[a.range].insert(c.type);
      for (const std::string& w : a.choices)
        if (std::find(g.choices.begin(), g.choices.end(), w) == g.choices.end()) g.choices.push_back(w);
    }
  // A type key is a word, one of its stage's registered types in the dimensions that read it (the
  // parsers hand the name to the registry, which knows them).
  for (auto& [path, g] : keys)
    if (is_type_key(path)) {
      const StageKind* kind = kind_of_section(top_of(path));
      if (!kind) continue;
      std::set<int> dims;
      for (const Context& c : g.readers) dims.insert(c.dim);
      g.kinds = {KeyAsk::Kind::Choice};
      g.choices.clear();
      for (const auto& [type, dim] : registered(*kind))
        if (dims.count(dim) && std::find(g.choices.begin(), g.choices.end(), type) == g.choices.end())
          g.choices.push_back(type);
    }
  // A section is read by whatever reads the keys in it (the 2D surface types are handed the
  // surface section, and read nothing there).
  for (auto& [path, g] : keys) {
    if (std::find(g.kinds.begin(), g.kinds.end(), KeyAsk::Kind::Section) == g.kinds.end() &&
        std::find(g.kinds.begin(), g.kinds.end(), KeyAsk::Kind::SectionList) == g.kinds.end())
      continue;
    std::set<Context> inner;
    for (const auto& [other, h] : keys)
      if (other.rfind(path + ".", 0) == 0 || other.rfind(path + "[].", 0) == 0) inner.insert(h.readers.begin(), h.readers.end());
    if (!inner.empty()) g.readers = inner;
  }

  std::map<std::string, const KeyNote*> notes;
  for (const KeyNote& n : key_notes()) {
    std::string key = n.key;
    const bool study = key.rfind("study:", 0) == 0;
    if ((document == "study") != study) continue;
    notes[study ? key.substr(6) : key] = &n;
  }
  std::set<std::string> described;
  std::set<std::string> maps;  // top-level keys holding keys
  for (const auto& kv : keys)
    if (kv.first.find_first_of(".[") != std::string::npos) maps.insert(top_of(kv.first));

  // Parents before their keys, siblings in the order they were first asked.
  auto sort_key = [&](const std::string& path) {
    std::vector<std::size_t> k;
    std::size_t from = 0;
    while (true) {
      const std::size_t dot = path.find('.', from);
      std::string prefix = path.substr(0, dot);
      if (prefix.size() > 2 && prefix.compare(prefix.size() - 2, 2, "[]") == 0) prefix.resize(prefix.size() - 2);
      const auto it = keys.find(prefix);
      k.push_back(it == keys.end() ? 0 : it->second.order);
      if (dot == std::string::npos) break;
      from = dot + 1;
    }
    return k;
  };
  std::vector<std::string> paths;
  for (const auto& kv : keys) paths.push_back(kv.first);
  std::sort(paths.begin(), paths.end(), [&](const std::string& a, const std::string& b) { return sort_key(a) < sort_key(b); });

  const std::string where = document == "study" ? "study file key " : "key ";
  for (const std::string& path : paths) {
    const Gathered& g = keys.at(path);
    if (!g.in_good_parse) {
      ref.problems.push_back(where + path + " is reached only by configurations that fail to parse");
      continue;
    }
    if (g.kinds.empty()) {
      ref.problems.push_back(where + path + " is only ever tested for presence: give it in a configuration of apps/keys.cpp");
      continue;
    }
    KeyEntry e;
    e.document = document;
    e.section = section_of(document, path, maps);
    e.path = path;
    std::vector<std::string> kinds;
    for (KeyAsk::Kind k : g.kinds) kinds.push_back(kind_name(k));
    e.type = join(kinds, " or ");
    if (!g.choices.empty()) {
      e.range = join(g.choices, ", ");
    } else if (g.ranges.size() == 1) {
      e.range = g.ranges.begin()->first;
    } else {
      std::vector<std::string> parts;
      for (const auto& [range, types] : g.ranges)
        parts.push_back(range + " (" + join(std::vector<std::string>(types.begin(), types.end()), ", ") + ")");
      e.range = join(parts, "; ");
    }
    e.read_by = readers_text(document, path, g.readers);
    // The default recorded: one value, one per dimension, or none (a section, an empty text).
    bool concrete = false;  // a single value the getters gave
    {
      const bool container = std::all_of(g.kinds.begin(), g.kinds.end(), [](KeyAsk::Kind k) {
        return k == KeyAsk::Kind::Section || k == KeyAsk::Kind::SectionList || k == KeyAsk::Kind::Raw;
      });
      std::set<std::string> all;
      bool one_per_dim = true;
      for (const auto& [dim, values] : g.fallbacks) {
        all.insert(values.begin(), values.end());
        one_per_dim = one_per_dim && values.size() == 1;
      }
      // An empty default (an empty text, path or list) is no value: shown as — like an absent one.
      auto shown = [](const std::string& v) { return v.empty() ? std::string("—") : v; };
      if (container || all.empty() || (all.size() == 1 && (all.begin()->empty() || *all.begin() == "[]"))) {
        e.fallback = "—";
        e.fallback_is_value = false;
      } else if (all.size() == 1) {
        e.fallback = *all.begin();
        concrete = true;
      } else if (one_per_dim) {
        std::vector<std::string> parts;  // "2D 10, 3D 6": "; " separates the terminal's fields
        for (const auto& [dim, values] : g.fallbacks) parts.push_back(std::to_string(dim) + "D " + shown(*values.begin()));
        e.fallback = join(parts, ", ");
        e.fallback_is_value = false;
      } else {
        e.fallback = join(std::vector<std::string>(all.begin(), all.end()), " or ");
      }
    }
    auto note = notes.find(path);
    for (const auto& [from, to] : note_aliases)
      if (note == notes.end() && path.rfind(from, 0) == 0) note = notes.find(to + path.substr(std::string(from).size()));
    const bool several = !concrete && e.fallback_is_value && e.fallback != "—";
    if (note == notes.end()) {
      ref.problems.push_back(where + path + " has no description in apps/key_notes.cpp");
    } else {
      e.description = note->second->text;
      if (note->second->fallback) {
        // A note says what a recorded default cannot (computed, required, several): it must not
        // contradict a single value the parser gives.
        if (concrete && !note->second->computed && e.fallback != note->second->fallback)
          ref.problems.push_back(where + path + ": the default in apps/key_notes.cpp ('" + note->second->fallback +
                                 "') is not the parser's (" + e.fallback + ")");
        e.fallback = note->second->fallback;
        e.fallback_is_value = false;
      } else if (several) {
        ref.problems.push_back(where + path + " has several defaults (" + e.fallback + "): say which in apps/key_notes.cpp");
      }
      described.insert(note->first);
    }
    ref.entries.push_back(e);
  }
  // A list of sections whose items were never given: their keys are missing.
  for (const KeyEntry& e : ref.entries)
    if (e.document == document && e.type.find("list of sections") != std::string::npos &&
        !std::any_of(ref.entries.begin(), ref.entries.end(),
                     [&](const KeyEntry& o) { return o.document == document && o.path.rfind(e.path + "[].", 0) == 0; }))
      ref.problems.push_back(where + e.path + " is a list whose items no configuration gave: give one in apps/keys.cpp");
  for (const auto& [path, note] : notes) {
    (void)note;
    if (described.count(path)) continue;
    ref.problems.push_back((document == "study" ? "study:" : "") + path +
                           ": described in apps/key_notes.cpp but no parser asks for it");
  }
}

}  // namespace

KeyReference collect_key_reference() {
  KeyReference ref;
  std::set<std::tuple<std::string, std::string, int>> selected;
  const Explored run = explore(run_seeds(), [&](const std::string& text) { return parse_run(text, selected); });
  const Explored study = explore({{"a study", study_seed}}, parse_study);
  ref.problems = run.problems;
  ref.problems.insert(ref.problems.end(), study.problems.begin(), study.problems.end());
  // Point 1: every registered type was selected by some configuration.
  for (StageKind k : all_stage_kinds)
    for (const auto& [type, dim] : registered(k))
      if (!selected.count({stage_kind_name(k), type, dim}))
        ref.problems.push_back(std::string(stage_kind_name(k)) + " type '" + type + "' (" + std::to_string(dim) +
                               "D) is selected by no configuration of apps/keys.cpp: add it to type_seeds");
  add_entries("run", run, ref);
  add_entries("study", study, ref);
  // Sections in the order of their first key in key_notes(), the reference's reading order (a
  // section without notes last, already a problem).
  for (const KeyNote& n : key_notes()) {
    const std::string key = n.key;
    const bool of_study = key.rfind("study:", 0) == 0;
    for (const KeyEntry& e : ref.entries)
      if ((e.document == "study") == of_study && e.path == (of_study ? key.substr(6) : key) &&
          std::find(ref.sections.begin(), ref.sections.end(), e.section) == ref.sections.end())
        ref.sections.push_back(e.section);
  }
  for (const KeyEntry& e : ref.entries)
    if (std::find(ref.sections.begin(), ref.sections.end(), e.section) == ref.sections.end()) ref.sections.push_back(e.section);
  std::stable_sort(ref.entries.begin(), ref.entries.end(), [&](const KeyEntry& a, const KeyEntry& b) {
    const auto ia = std::find(ref.sections.begin(), ref.sections.end(), a.section);
    const auto ib = std::find(ref.sections.begin(), ref.sections.end(), b.section);
    return ia < ib;
  });
  return ref;
}

// ---- printing ----------------------------------------------------------------------------------

namespace {

// "number in [0, 1]", "integer in 1..4", "number > 0", "word: sphere, box", "bool", ...
std::string value_text(const KeyEntry& e) {
  if (e.range.empty()) return e.type;
  const char c = e.range[0];
  if (c == '>' || c == '<') return e.type + " " + e.range;
  if (c == '[' || c == '(' || (c >= '0' && c <= '9') || c == '-') return e.type + " in " + e.range;
  return e.type + ": " + e.range;
}

// The line a section's heading carries: its own key's description.
std::string section_line(const KeyReference& r, const std::string& section) {
  if (section == "top") return "the run's own values";
  if (section == "study") return "a study file of plaf compare-attenuation STUDY.yaml (its own keys, not a run's)";
  for (const KeyEntry& e : r.entries)
    if (e.document == "run" && e.path == section) return e.description;
  return "";
}

std::string cell(std::string s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

const char* markdown_intro = R"(# Configuration keys

Generated by `plaf keys --markdown > docs/config.md` from the parsers themselves (apps/keys.h):
do not edit it by hand. A test (`tests/apps/keys_test.cpp`) fails when it differs from what the
code prints, so it lists exactly the keys the parsers accept. `plaf keys [SECTION]` prints the
same reference in a terminal; `plaf plugins` lists the registered types.

## How a configuration is structured

A run configuration (`plaf run CONFIG.yaml`) is one YAML map. Its top-level values name the run
and its order; each stage of the pipeline has a section, chosen by its `type:` among the
registered plugin types, and the chosen type reads its own keys there:

```yaml
name: my_body                 # the output files' base name
order: 3                      # geometry order Q of the curved cells (1..4)
geometry: {type: surface_file, file: body.stl}   # what to mesh; 3D types make a 3D run
metric: {type: wall_power_law, h0: 1.0e-4, growth: 1.2, h_wall_max: 0.05, h_max: 1}
surface: {ridge_angle_deg: 30}                   # 3D only: the surface mesh
layers: {type: extrude, max: 30}                 # prismatic layers; absent: none
fill: {type: tetgen}                             # the fill to the farfield; absent: none
output: {formats: [msh, vtu, report, png]}
```

Runnable cases are in `configs/`. Besides the stages, `extrude:` makes a 2D section a 3D run,
`limits:` bounds the run's size and `validity:` the certification, and `output:` says what is
written. Reading is strict: an unknown key, a key given twice, a value of the wrong type or out of
its range stops the run before anything is written, with one line naming the file, line, column
and key (`config.yaml:7:3: unknown key 'layers.hieght' (known here: ...)`, exit code 1). A key
valid for one type is unknown to another: the column *read by* says which types (or, for a
section without types, which dimensions) read it; a key read by all types of its section says
*all types*. The keys of type *path* are relative to the configuration's folder, or `data:REL` in
the data root (docs/data.md); `output.dir` is text, used as given (relative to the working
directory). In key paths, `[]` stands for every item of a list: `geometry.bodies[].file` is
the `file` of each map in `bodies`. A default of — means that an absent key gives nothing (or
what its description says).
)";

}  // namespace

std::string key_reference_text(const KeyReference& r, const std::string& section) {
  if (!section.empty() && std::find(r.sections.begin(), r.sections.end(), section) == r.sections.end())
    throw ConfigError("unknown section '" + section + "' (known: " + join(r.sections, ", ") + ")");
  std::ostringstream out;
  for (const std::string& s : r.sections) {
    if (!section.empty() && s != section) continue;
    out << s << ": " << section_line(r, s) << "\n";
    for (const KeyEntry& e : r.entries)
      if (e.section == s)
        out << "  " << e.path << "  (" << value_text(e) << "; default " << e.fallback << "; read by " << e.read_by
            << ")\n      " << e.description << "\n";
    out << "\n";
  }
  return out.str();
}

std::string key_reference_markdown(const KeyReference& r) {
  std::ostringstream out;
  out << markdown_intro;
  for (const std::string& s : r.sections) {
    out << "\n## " << (s == "study" ? "Study files" : "`" + s + "`") << "\n\n" << section_line(r, s) << ".\n\n";
    out << "| key | type | default | range or choices | read by | description |\n";
    out << "|---|---|---|---|---|---|\n";
    for (const KeyEntry& e : r.entries)
      if (e.section == s)
        out << "| `" << e.path << "` | " << cell(e.type) << " | " << (e.fallback_is_value ? "`" + cell(e.fallback) + "`" : cell(e.fallback))
            << " | " << (e.range.empty() ? "—" : cell(e.range)) << " | " << cell(e.read_by) << " | " << cell(e.description)
            << " |\n";
  }
  return out.str();
}

std::string key_probes_yaml() {
  std::set<std::tuple<std::string, std::string, int>> selected;
  const Explored run = explore(run_seeds(), [&](const std::string& text) { return parse_run(text, selected); });
  // (key, range or words) -> the configurations that read it so, in the order parsed.
  std::map<std::pair<std::string, std::string>, std::vector<std::string>> probes;
  for (const Parse& p : run.parses) {
    if (!p.ok) continue;
    for (const KeyAsk& a : p.asks) {
      if (is_type_key(a.path) || (a.range.empty() && a.kind != KeyAsk::Kind::Choice)) continue;
      const std::string range = a.kind == KeyAsk::Kind::Choice ? "words: " + join(a.choices, ", ") : a.range;
      std::vector<std::string>& configs = probes[{a.path, range}];
      if (configs.size() < 6 && std::find(configs.begin(), configs.end(), p.text) == configs.end())
        configs.push_back(p.text);
    }
  }
  YAML::Emitter e;
  e << YAML::BeginSeq;
  for (const auto& [key, configs] : probes) {
    e << YAML::BeginMap << YAML::Key << "key" << YAML::Value << key.first << YAML::Key << "range" << YAML::Value
      << key.second << YAML::Key << "configs" << YAML::Value << YAML::BeginSeq;
    for (const std::string& c : configs) e << YAML::Literal << c;
    e << YAML::EndSeq << YAML::EndMap;
  }
  e << YAML::EndSeq;
  return std::string(e.c_str()) + "\n";
}

int keys_command(const std::optional<std::string>& section, bool markdown) {
  register_all_plugins();
  const KeyReference r = collect_key_reference();
  for (const std::string& p : r.problems) std::cerr << "plaf: warning: key reference: " << p << '\n';
  if (section && section->empty())
    throw ConfigError("unknown section '' (known: " + join(r.sections, ", ") + ")");
  std::cout << (markdown ? key_reference_markdown(r) : key_reference_text(r, section.value_or("")));
  return 0;
}

}  // namespace plaf
