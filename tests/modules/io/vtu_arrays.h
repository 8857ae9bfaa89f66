// SPDX-License-Identifier: MIT
// The numbers of a .vtu file's DataArray, read by the tests from the VTK XML format's description:
// a text scan of an ASCII array, or the appended zlib-compressed data of a binary file.
#pragma once

#include <doctest/doctest.h>
#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace plaf::test {

// The values of one appended, zlib-compressed DataArray (VTK's layout with header_type UInt64:
// the number of blocks, the block size, the last partial block's size or 0, each block's
// compressed size, then the blocks), decoded by this test from the format's description.
inline std::vector<double> appended_array(const std::string& file, const std::string& tag) {
  auto attribute = [&tag](const std::string& name) {
    const std::size_t at = tag.find(" " + name + "=\"");
    REQUIRE_MESSAGE(at != std::string::npos, "no ", name, " in ", tag);
    const std::size_t b = at + name.size() + 3;
    return tag.substr(b, tag.find('"', b) - b);
  };
  const std::size_t data = file.find("<AppendedData encoding=\"raw\">");
  REQUIRE(data != std::string::npos);
  const std::size_t start = file.find('_', data) + 1;
  std::size_t at = start + std::stoull(attribute("offset"));
  auto u64 = [&] {
    std::uint64_t v = 0;
    REQUIRE(at + 8 <= file.size());
    std::memcpy(&v, file.data() + at, 8);
    at += 8;
    return v;
  };
  const std::uint64_t blocks = u64(), block_size = u64(), last = u64();
  std::vector<std::uint64_t> sizes;
  for (std::uint64_t b = 0; b < blocks; ++b) sizes.push_back(u64());
  std::string raw;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    uLongf n = static_cast<uLongf>(b + 1 == blocks && last != 0 ? last : block_size);
    std::string out(n, '\0');
    REQUIRE(uncompress(reinterpret_cast<Bytef*>(out.data()), &n, reinterpret_cast<const Bytef*>(file.data() + at),
                       static_cast<uLong>(sizes[b])) == Z_OK);
    raw.append(out.data(), n);
    at += sizes[b];
  }
  const std::string type = attribute("type");
  auto decode = [&raw]<class T>(T) {
    REQUIRE(raw.size() % sizeof(T) == 0);
    std::vector<double> v(raw.size() / sizeof(T));
    for (std::size_t i = 0; i < v.size(); ++i) {
      T x;
      std::memcpy(&x, raw.data() + i * sizeof(T), sizeof(T));
      v[i] = static_cast<double>(x);
    }
    return v;
  };
  if (type == "Float64") return decode(double{});
  if (type == "Int64") return decode(std::int64_t{});
  if (type == "Int32") return decode(std::int32_t{});
  REQUIRE(type == "UInt8");
  return decode(std::uint8_t{});
}

// The numbers of the DataArray named `name`: a plain text scan of the XML, or the decoded
// appended data of a binary file.
inline std::vector<double> vtu_data_array(const std::string& xml, const std::string& name) {
  const std::size_t at = xml.find("Name=\"" + name + "\"");
  REQUIRE_MESSAGE(at != std::string::npos, "no DataArray ", name);
  const std::size_t begin = xml.find('>', at) + 1;
  const std::string tag = xml.substr(xml.rfind('<', at), begin - xml.rfind('<', at));
  if (tag.find("format=\"appended\"") != std::string::npos) return appended_array(xml, tag);
  const std::size_t end = xml.find("</DataArray>", begin);
  REQUIRE(end != std::string::npos);
  std::istringstream in(xml.substr(begin, end - begin));
  std::vector<double> values;
  std::string token;
  while (in >> token) values.push_back(std::strtod(token.c_str(), nullptr));
  return values;
}

}  // namespace plaf::test
