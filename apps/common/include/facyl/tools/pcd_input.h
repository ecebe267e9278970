/*
 * facyl: reading PCD files in the tools without trusting them.
 *
 * PCL's reader trusts the header: a directory given as a file makes it wait forever, a
 * header claiming 2e8 points in 300 bytes makes it allocate gigabytes before it notices, and a
 * header without fields makes it dereference nothing. Here the path and the header are checked
 * against the file first, then PCL reads.
 */
#pragma once

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <Eigen/Geometry>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace facyl_cli {

inline bool
hasField(const pcl::PCLPointCloud2& blob, const std::string& name)
{
  for (const auto& f : blob.fields)
    if (f.name == name)
      return true;
  return false;
}

/** \a text (from a file) as a message quotes it: at most \a max bytes, each byte that is not
 * printable ASCII written as \\xNN, so that a binary file's header gives a readable one-line,
 * valid-UTF-8 message. */
inline std::string
quotedFileText(const std::string& text, std::size_t max = 40)
{
  static const char hex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < max; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f)
      out += static_cast<char>(c);
    else {
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

/** What a PCD header says (the part the checks need). */
struct PcdHeader {
  std::vector<std::string> fields;
  std::vector<std::uint64_t> size, count;
  std::vector<char> type;
  std::uint64_t width{0}, height{1}, points{0};
  std::string data;           ///< ascii | binary | binary_compressed
  std::size_t data_offset{0}; ///< bytes before the data
  bool has_points{false};

  /** Bytes per point. */
  std::uint64_t pointStep() const
  {
    std::uint64_t step = 0;
    for (std::size_t i = 0; i < size.size(); ++i)
      step += size[i] * count[i];
    return step;
  }
};

/** The largest cloud a tool reads (bytes of point data): a guard against headers that claim
 * more than any sensor frame (a 4K RGB-D frame with normals is ~0.4 GB). */
constexpr std::uint64_t kMaxCloudBytes = std::uint64_t{2} << 30;

/** Parses the header of \a in (at most 64 KiB or 200 lines). \return an empty string, or what
 * is wrong with it. */
inline std::string
parsePcdHeader(std::istream& in, PcdHeader& h)
{
  std::string line;
  std::size_t offset = 0;
  for (int lines = 0; lines < 200 && offset < 65536; ++lines) {
    if (!std::getline(in, line))
      return "not a PCD file (the header ends before DATA)";
    offset += line.size() + 1;
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream words(line);
    std::string key;
    words >> key;
    const auto numbers = [&](std::vector<std::uint64_t>& out) {
      out.clear();
      std::string w;
      while (words >> w) {
        if (w.find_first_not_of("0123456789") != std::string::npos || w.size() > 12)
          return false;
        out.push_back(std::stoull(w));
      }
      return !out.empty();
    };
    const auto number = [&](std::uint64_t& out) {
      std::vector<std::uint64_t> v;
      if (!numbers(v) || v.size() != 1)
        return false;
      out = v[0];
      return true;
    };
    if (key == "VERSION" || key == "VIEWPOINT")
      continue;
    if (key == "FIELDS" || key == "COLUMNS") {
      std::string w;
      while (words >> w)
        h.fields.push_back(w);
    }
    else if (key == "SIZE") {
      if (!numbers(h.size))
        return "the PCD header's SIZE is not a list of numbers";
    }
    else if (key == "COUNT") {
      if (!numbers(h.count))
        return "the PCD header's COUNT is not a list of numbers";
    }
    else if (key == "TYPE") {
      std::string w;
      while (words >> w)
        h.type.push_back(w.size() == 1 ? w[0] : '?');
    }
    else if (key == "WIDTH") {
      if (!number(h.width))
        return "the PCD header's WIDTH is not a number";
    }
    else if (key == "HEIGHT") {
      if (!number(h.height))
        return "the PCD header's HEIGHT is not a number";
    }
    else if (key == "POINTS") {
      if (!number(h.points))
        return "the PCD header's POINTS is not a number";
      h.has_points = true;
    }
    else if (key == "DATA") {
      words >> h.data;
      h.data_offset = offset;
      break;
    }
    else
      return "not a PCD file (unknown header line '" + quotedFileText(line) + "')";
  }
  if (h.data.empty())
    return "not a PCD file (no DATA line in the header)";
  if (h.fields.empty())
    return "not a PCD file (no FIELDS)";
  if (h.count.empty())
    h.count.assign(h.fields.size(), 1);
  if (h.size.size() != h.fields.size() || h.type.size() != h.fields.size() ||
      h.count.size() != h.fields.size())
    return "the PCD header's FIELDS, SIZE, TYPE and COUNT do not have the same length";
  for (std::size_t i = 0; i < h.fields.size(); ++i)
    if ((h.size[i] != 1 && h.size[i] != 2 && h.size[i] != 4 && h.size[i] != 8) ||
        (h.type[i] != 'F' && h.type[i] != 'I' && h.type[i] != 'U') || h.count[i] == 0 ||
        h.count[i] > 4096)
      return "the PCD header describes field '" + quotedFileText(h.fields[i]) +
             "' with an invalid SIZE, TYPE or COUNT";
  if (!h.has_points)
    h.points = h.width * h.height;
  if (h.width == 0 ? h.points != 0 : h.width * h.height != h.points)
    return "the PCD header's WIDTH x HEIGHT is not POINTS";
  return {};
}

/** Checks \a h against the \a file_size bytes of its file: the data it announces must fit.
 * \return an empty string, or what is wrong. */
inline std::string
checkPcdSize(std::istream& in, const PcdHeader& h, std::uint64_t file_size)
{
  const std::uint64_t step = h.pointStep();
  if (h.points > kMaxCloudBytes || step > kMaxCloudBytes || h.points * step > kMaxCloudBytes)
    return "the PCD header claims " + std::to_string(h.points) + " points of " +
           std::to_string(step) + " bytes: more than facyl reads (2 GiB)";
  const std::uint64_t data_bytes = file_size > h.data_offset ? file_size - h.data_offset : 0;
  const std::uint64_t need = h.points * step;
  const std::string truncated =
    "the PCD file is truncated: its header claims " + std::to_string(h.points) + " points, ";
  if (h.data == "binary") {
    if (need > data_bytes)
      return truncated + std::to_string(need) + " bytes, the file holds " +
             std::to_string(data_bytes);
  }
  else if (h.data == "ascii") {
    // At least one character and one separator per value.
    std::uint64_t values = 0;
    for (const auto c : h.count)
      values += c;
    if (h.points * values * 2 > data_bytes + 1)
      return truncated + "the file holds " + std::to_string(data_bytes) + " bytes of text";
  }
  else if (h.data == "binary_compressed") {
    std::uint32_t sizes[2] = {0, 0};
    in.read(reinterpret_cast<char*>(sizes), sizeof sizes);
    if (!in)
      return "the PCD file is truncated: no compressed data";
    if (sizes[1] != need)
      return "the PCD file is corrupt: its compressed data unpacks to " + std::to_string(sizes[1]) +
             " bytes, its header needs " + std::to_string(need);
    // LZF encodes at most 264 bytes in 3.
    if (sizes[0] > data_bytes || static_cast<std::uint64_t>(sizes[1]) > 90ull * sizes[0] + 1024)
      return "the PCD file is corrupt or truncated: " + std::to_string(sizes[0]) +
             " compressed bytes cannot hold " + std::to_string(sizes[1]);
  }
  else
    return "the PCD header's DATA '" + quotedFileText(h.data) +
           "' is not ascii, binary or binary_compressed";
  return {};
}

/** Where the sensor was, as the PCD file's VIEWPOINT says. */
struct Viewpoint {
  Eigen::Vector4f origin{Eigen::Vector4f::Zero()};
  Eigen::Quaternionf orientation{Eigen::Quaternionf::Identity()};
};

/** The checks of a PCD file that need only its header: a regular file, a header that agrees
 * with the file's length, x, y, z as 4-byte floats, at least one point. Fills \a h.
 * \return an empty string, or why facyl would refuse \a file. */
inline std::string
checkPcdHeader(const std::string& file, PcdHeader& h)
{
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec || !std::filesystem::exists(status))
    return "cannot open the file";
  if (std::filesystem::is_directory(status))
    return "it is a directory, not a PCD file";
  if (!std::filesystem::is_regular_file(status))
    return "not a regular file (a device, pipe or socket), not a PCD file";
  const std::uint64_t file_size = std::filesystem::file_size(file, ec);
  if (ec)
    return "cannot read the file's size";
  std::ifstream in(file, std::ios::binary);
  if (!in)
    return "cannot open the file";
  std::string why = parsePcdHeader(in, h);
  if (why.empty())
    why = checkPcdSize(in, h, file_size);
  if (!why.empty())
    return why;
  for (const char* axis : {"x", "y", "z"}) {
    std::size_t i = 0;
    while (i < h.fields.size() && h.fields[i] != axis)
      ++i;
    if (i == h.fields.size())
      return "the cloud has no x, y, z fields";
    if (h.type[i] != 'F' || h.size[i] != 4 || h.count[i] != 1)
      return std::string("the coordinates are stored as ") +
             (h.type[i] == 'F' ? "float" : (h.type[i] == 'I' ? "signed int" : "unsigned int")) +
             std::to_string(8 * h.size[i]) + " (field " + axis + ": TYPE " + h.type[i] + ", SIZE " +
             std::to_string(h.size[i]) + ", COUNT " + std::to_string(h.count[i]) +
             "); facyl reads 4-byte floats (TYPE F, SIZE 4), as PCL's point types hold";
  }
  if (h.points == 0)
    return "the cloud is empty (POINTS 0)";
  return "";
}

/** Reads \a file into \a blob (and its VIEWPOINT into \a viewpoint): regular files only, the
 * header checked against the file's length before anything is allocated (checkPcdHeader), x,
 * y, z as 4-byte floats. \return an empty string, or why the file cannot be used. */
inline std::string
readPcd(const std::string& file, pcl::PCLPointCloud2& blob, Viewpoint* viewpoint = nullptr)
{
  PcdHeader h;
  if (std::string why = checkPcdHeader(file, h); !why.empty())
    return why;
  pcl::PCDReader reader;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0;
  if (reader.read(file, blob, origin, orientation, version) < 0)
    return "the PCD file is corrupt or truncated";
  if (blob.data.size() != static_cast<std::size_t>(blob.width) * blob.height * blob.point_step)
    return "the PCD file is corrupt (its data do not fill its points)";
  if (viewpoint) {
    viewpoint->origin = origin;
    viewpoint->orientation = orientation;
  }
  return {};
}

} // namespace facyl_cli
