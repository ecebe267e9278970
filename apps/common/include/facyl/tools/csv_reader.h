/*
 * facyl: the one reader of the label tables the tools and the tests read (the real data's
 * labels.csv files): rows of comma-separated fields, a field in double quotes may hold commas.
 */
#pragma once

#include <istream>
#include <string>
#include <vector>

namespace facyl_cli {

/** \brief The fields of one CSV \a line: commas separate them except between double quotes,
 * which are dropped (no escaped quotes: a doubled quote inside quotes closes and opens again
 * and so vanishes). "a,\"b, c\",d" gives a | b, c | d; an empty line one empty field. */
inline std::vector<std::string>
splitCsvLine(const std::string& line)
{
  std::vector<std::string> fields;
  std::string cur;
  bool quoted = false;
  for (const char ch : line) {
    if (ch == '"')
      quoted = !quoted;
    else if (ch == ',' && !quoted) {
      fields.push_back(cur);
      cur.clear();
    }
    else
      cur += ch;
  }
  fields.push_back(cur);
  return fields;
}

/** \brief The rows of the CSV table \a in after its header line (skipped), each split by
 * splitCsvLine. */
inline std::vector<std::vector<std::string>>
readCsvRows(std::istream& in)
{
  std::vector<std::vector<std::string>> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line))
    rows.push_back(splitCsvLine(line));
  return rows;
}

} // namespace facyl_cli
