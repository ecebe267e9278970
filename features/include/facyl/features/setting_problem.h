/*
 * facyl: the form of validate()'s messages, shared by the settings structs.
 */
#pragma once

#include <sstream>
#include <string>

namespace facyl {

/** \brief validate()'s message for a setting that breaks its rule: "NAME VALUE RULE" (e.g.
 * "neighbours 3 is not in [5, 200]"). With \a rule_out, the RULE alone goes there too: the
 * tools and the Python module print it after the option that set the value, as the user wrote
 * it ("option --neighbours: 3 is not in [5, 200]"), so that a range has one home, validate().
 * \a value is printed as an std::ostream prints it. */
template <typename T>
std::string
settingProblem(const std::string& name, const T& value, const std::string& rule,
               std::string* rule_out)
{
  if (rule_out)
    *rule_out = rule;
  std::ostringstream s;
  s << name << ' ' << value << ' ' << rule;
  return s.str();
}

} // namespace facyl
