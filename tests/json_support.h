// SPDX-License-Identifier: MIT
// A strict reader of one JSON object per line (RFC 8259), for the tests of plaf's JSON lines
// (modules/pipeline/progress.h): it accepts a line only if it is exactly one JSON object, and
// gives its top-level members (strings unescaped, numbers parsed, other values as their text).
#pragma once

#include <cctype>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>

namespace plaf::test {

struct JsonMember {
  enum Kind { String, Number, Other } kind = Other;  // Other: true, false, null, an object, an array
  std::string text;                                  // a string's value, else the value's JSON text
  double number = 0;
};

class JsonLine {
 public:
  // The object's members, or nothing if `line` is not exactly one JSON object.
  static std::optional<std::map<std::string, JsonMember>> parse(const std::string& line) {
    JsonLine p(line);
    std::map<std::string, JsonMember> members;
    p.space();
    if (!p.object(&members)) return std::nullopt;
    p.space();
    if (p.at_ != line.size()) return std::nullopt;
    return members;
  }

 private:
  explicit JsonLine(const std::string& s) : s_(s) {}
  bool eat(char c) {
    space();
    if (at_ < s_.size() && s_[at_] == c) {
      ++at_;
      return true;
    }
    return false;
  }
  void space() {
    while (at_ < s_.size() && (s_[at_] == ' ' || s_[at_] == '\t' || s_[at_] == '\n' || s_[at_] == '\r')) ++at_;
  }
  bool object(std::map<std::string, JsonMember>* members) {
    if (!eat('{')) return false;
    if (eat('}')) return true;
    do {
      space();
      std::string key;
      if (!string(&key) || !eat(':')) return false;
      JsonMember m;
      if (!value(&m)) return false;
      if (members && !members->emplace(key, m).second) return false;  // a key twice
    } while (eat(','));
    return eat('}');
  }
  bool array() {
    if (!eat('[')) return false;
    if (eat(']')) return true;
    do {
      JsonMember m;
      if (!value(&m)) return false;
    } while (eat(','));
    return eat(']');
  }
  bool value(JsonMember* m) {
    space();
    const std::size_t from = at_;
    if (at_ >= s_.size()) return false;
    const char c = s_[at_];
    if (c == '"') {
      m->kind = JsonMember::String;
      return string(&m->text);
    }
    bool ok = false;
    if (c == '{')
      ok = object(nullptr);
    else if (c == '[')
      ok = array();
    else if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) {
      if (!number()) return false;
      m->kind = JsonMember::Number;
      m->text = s_.substr(from, at_ - from);
      m->number = std::strtod(m->text.c_str(), nullptr);
      return true;
    } else
      for (const char* word : {"true", "false", "null"})
        if (s_.compare(at_, std::char_traits<char>::length(word), word) == 0) {
          at_ += std::char_traits<char>::length(word);
          ok = true;
          break;
        }
    if (ok) m->text = s_.substr(from, at_ - from);
    return ok;
  }
  bool digits() {
    const std::size_t from = at_;
    while (at_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[at_]))) ++at_;
    return at_ > from;
  }
  bool number() {
    if (s_[at_] == '-') ++at_;
    if (at_ < s_.size() && s_[at_] == '0')
      ++at_;
    else if (!digits())
      return false;
    if (at_ < s_.size() && s_[at_] == '.' && (++at_, !digits())) return false;
    if (at_ < s_.size() && (s_[at_] == 'e' || s_[at_] == 'E')) {
      ++at_;
      if (at_ < s_.size() && (s_[at_] == '+' || s_[at_] == '-')) ++at_;
      if (!digits()) return false;
    }
    return true;
  }
  bool string(std::string* out) {
    if (at_ >= s_.size() || s_[at_] != '"') return false;
    ++at_;
    while (at_ < s_.size()) {
      const char c = s_[at_++];
      if (c == '"') return true;
      if (static_cast<unsigned char>(c) < 0x20) return false;  // raw control characters are not JSON
      if (c != '\\') {
        *out += c;
        continue;
      }
      if (at_ >= s_.size()) return false;
      const char e = s_[at_++];
      if (e == 'u') {
        if (at_ + 4 > s_.size()) return false;
        for (int k = 0; k < 4; ++k)
          if (!std::isxdigit(static_cast<unsigned char>(s_[at_ + static_cast<std::size_t>(k)]))) return false;
        const unsigned long code = std::strtoul(s_.substr(at_, 4).c_str(), nullptr, 16);
        *out += code < 0x80 ? static_cast<char>(code) : '?';  // (the tests compare ASCII text)
        at_ += 4;
        continue;
      }
      const std::string escapes = "\"\\/bfnrt", meant = "\"\\/\b\f\n\r\t";
      const std::size_t k = escapes.find(e);
      if (k == std::string::npos) return false;
      *out += meant[k];
    }
    return false;
  }

  const std::string& s_;
  std::size_t at_ = 0;
};

}  // namespace plaf::test
