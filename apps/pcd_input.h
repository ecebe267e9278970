/*
 * facyl: reading PCD files in the tools without trusting them.
 */
#pragma once

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <fstream>
#include <string>

namespace facyl_cli {

inline bool
hasField(const pcl::PCLPointCloud2& blob, const std::string& name)
{
  for (const auto& f : blob.fields)
    if (f.name == name)
      return true;
  return false;
}

/** Reads \a file into \a blob. PCL 1.13's PCDReader::read dereferences a header without
 * fields (any non-PCD file), so the header is read and checked first.
 * \return an empty string, or why the file cannot be used. */
inline std::string
readPcd(const std::string& file, pcl::PCLPointCloud2& blob)
{
  if (!std::ifstream(file).good())
    return "cannot open the file";
  pcl::PCDReader reader;
  pcl::PCLPointCloud2 header;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_index = 0;
  if (reader.readHeader(file, header, origin, orientation, version, data_type, data_index) < 0 ||
      header.fields.empty() || header.point_step == 0)
    return "not a PCD file (no valid header)";
  if (reader.read(file, blob) < 0)
    return "the PCD file is corrupt or truncated";
  if (!hasField(blob, "x") || !hasField(blob, "y") || !hasField(blob, "z"))
    return "the cloud has no x, y, z fields";
  return {};
}

} // namespace facyl_cli
