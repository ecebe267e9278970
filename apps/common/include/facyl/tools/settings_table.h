/*
 * facyl: settings tables. Each settings struct that the tools and the Python module expose has
 * one table, a row (Option) per option: its name, the field it sets, the kind of value it takes
 * and its help text. The tools' help, the tools' parser and the Python module's keywords all
 * read the table; a default is the value of a default-constructed struct, a range is checked
 * by the struct's validate() (its one home), which runs after every option applied, so that
 * its complaint names the option that caused it.
 */
#pragma once

#include <facyl/tools/cli.h>

#include <Eigen/Core>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace facyl_cli {

/** How options are named to the user: the tools' "--radius-limits", or the Python module's
 * keyword "radius_limits" (the same name with '_' for '-'). */
struct Vocabulary {
  bool python{false};

  /** Option \a name ("radius-limits") as the user writes it. */
  std::string option(const std::string& name) const
  {
    if (!python)
      return "--" + name;
    std::string keyword = name;
    std::replace(keyword.begin(), keyword.end(), '-', '_');
    return keyword;
  }
  /** Option \a name with the word \a value: "--units mm", or units="mm". */
  std::string option(const std::string& name, const std::string& value) const
  {
    return python ? option(name) + "=\"" + value + "\"" : option(name) + " " + value;
  }
};

/** The kind of value an option takes. */
enum class ValueKind {
  Switch,  ///< none: given or not (Python: True; False and None are "not given")
  Integer, ///< digits with an optional minus sign (Python: an int)
  Number,  ///< a finite number
  Pair,    ///< "A,B" (Python: two numbers)
  Vector3, ///< "x,y,z" (Python: three numbers)
  Word     ///< a word (Python: a str)
};

/** An option's value as given: read by the option's kind, and as the user wrote it. */
struct OptionValue {
  /** For messages: the text typed (a word in quotes: 'x'), or Python's repr of the value. */
  std::string written;
  std::string word; ///< Word; or one of the words a Pair or Number option accepts
  long long integer{0};
  bool overflow{false}; ///< Integer: beyond a 64-bit integer (saturated in integer)
  double number{0.0};
  std::pair<double, double> pair{0.0, 0.0};
  Eigen::Vector3f vector{Eigen::Vector3f::Zero()};
};

/** What an option's set() may ask about the others given with it. */
struct OptionContext {
  Vocabulary say; ///< how options are named in messages
  /** The value given for option \a name of the same table; nullptr when not given. */
  std::function<const OptionValue*(const std::string& name)> given;
};

/** One option of the settings struct S. */
template <typename S> struct Option {
  std::string name;    ///< "radius-limits": the tools' --radius-limits, Python's radius_limits
  std::string metavar; ///< "A,B" in the help; empty for a switch
  ValueKind kind{ValueKind::Switch};
  /** The help text after the option's name; lines are separated by '\n' and indented to the
   * table's column; "{}" stands for the default (show of a default-constructed struct). */
  std::string help;
  /** Sets the field(s) from a value of the option's kind.
   * \throws std::invalid_argument saying what is wrong; the message follows "option --NAME: ". */
  std::function<void(S&, const OptionValue&, const OptionContext&)> set;
  /** The field's value as the help prints it ("{}"); empty when the help prints none. */
  std::function<std::string(const S&)> show;
  std::vector<std::string> words; ///< words a Pair or Number option takes too ("auto")
  std::string heading;            ///< lines of the help before this option (a section's title)
  std::string alias;              ///< an old spelling still read ("k" for "neighbours")
  bool first{false};              ///< applied before the others (their values depend on it)
  bool hidden{false};             ///< not in the help (an old spelling the help mentions)
  bool tool_only{false};          ///< not a Python keyword
};

/** The options of the settings struct S, in the order of the help. */
template <typename S> struct SettingsTable {
  std::vector<Option<S>> options;
  std::size_t column{25}; ///< where the help's descriptions start
  /** The struct's validate(): "" or what is wrong; the rule broken alone through the pointer
   * when the message has the form "NAME VALUE RULE" (facyl::settingProblem). */
  std::function<std::string(const S&, std::string*)> validate;
  /** Options that exclude each other, and what to say when both are given (default: "--A and
   * --B exclude each other"). */
  struct Exclusion {
    std::string a, b, why;
  };
  std::vector<Exclusion> exclusive;

  /** The option named \a name, or spelled so by its alias; nullptr when none. */
  const Option<S>* find(const std::string& name) const
  {
    for (const auto& o : options)
      if (o.name == name || (!o.alias.empty() && o.alias == name))
        return &o;
    return nullptr;
  }
};

// ---------------------------------------------------------------------------- rows

/** Limits that a tool puts on a value where the struct's validate() sets none (a seed read
 * as a signed 64-bit integer, a length no scene needs); \a T: long long or double. */
template <typename T> struct Limits {
  T lo, hi;
  std::string text() const
  {
    std::ostringstream s;
    s << "[" << lo << ", " << hi << "]";
    return s.str();
  }
};

namespace detail {

/** \a v as T, saturated at T's limits: validate() then refuses it by its own range. */
template <typename T>
T
saturated(long long v)
{
  using L = std::numeric_limits<T>;
  if constexpr (std::is_signed_v<T>) {
    if (v < static_cast<long long>(L::lowest()))
      return L::lowest();
  }
  else if (v < 0)
    return 0;
  if (static_cast<unsigned long long>(std::max(v, 0LL)) > static_cast<unsigned long long>(L::max()))
    return L::max();
  return static_cast<T>(v);
}

template <typename S, typename Field>
std::function<std::string(const S&)>
showNumber(Field field)
{
  return [field](const S& s) {
    const auto& f = field(s);
    if constexpr (std::is_floating_point_v<std::decay_t<decltype(f)>>)
      return compactNumber(static_cast<float>(f));
    else
      return std::to_string(f);
  };
}

} // namespace detail

/** An option of a field that takes an integer; \a limits when validate() bounds it not.
 * \a field: `[](auto& s) -> auto& { return s.field; }`. */
template <typename S, typename Field>
Option<S>
integerOption(const std::string& name, const std::string& metavar, Field field,
              const std::string& help, std::optional<Limits<long long>> limits = std::nullopt)
{
  Option<S> o;
  o.name = name;
  o.metavar = metavar;
  o.kind = ValueKind::Integer;
  o.help = help;
  o.set = [field, limits](S& s, const OptionValue& v, const OptionContext&) {
    if (limits && (v.overflow || v.integer < limits->lo || v.integer > limits->hi))
      throw std::invalid_argument(v.written + " is not in " + limits->text());
    auto& f = field(s);
    f = detail::saturated<std::decay_t<decltype(f)>>(v.integer);
  };
  o.show = detail::showNumber<S>(field);
  return o;
}

/** An option of a field that takes a number; \a limits when validate() bounds it not. */
template <typename S, typename Field>
Option<S>
numberOption(const std::string& name, const std::string& metavar, Field field,
             const std::string& help, std::optional<Limits<double>> limits = std::nullopt)
{
  Option<S> o;
  o.name = name;
  o.metavar = metavar;
  o.kind = ValueKind::Number;
  o.help = help;
  o.set = [field, limits](S& s, const OptionValue& v, const OptionContext&) {
    if (limits && !(v.number >= limits->lo && v.number <= limits->hi))
      throw std::invalid_argument(v.written + " is not in " + limits->text());
    auto& f = field(s);
    f = static_cast<std::decay_t<decltype(f)>>(v.number);
  };
  o.show = detail::showNumber<S>(field);
  return o;
}

/** A switch that sets a field to \a value. */
template <typename S, typename Field, typename T>
Option<S>
switchOption(const std::string& name, Field field, T value, const std::string& help)
{
  Option<S> o;
  o.name = name;
  o.kind = ValueKind::Switch;
  o.help = help;
  o.set = [field, value](S& s, const OptionValue&, const OptionContext&) { field(s) = value; };
  return o;
}

/** "a, b or c". */
inline std::string
alternatives(const std::vector<std::string>& words)
{
  std::string out;
  for (std::size_t k = 0; k < words.size(); ++k)
    out += (k ? (k + 1 == words.size() ? " or " : ", ") : "") + words[k];
  return out;
}

/** An option of a field that takes one of \a choices (word, value), in the help's order. */
template <typename S, typename Field, typename T>
Option<S>
choiceOption(const std::string& name, const std::string& metavar, Field field,
             const std::vector<std::pair<std::string, T>>& choices, const std::string& help)
{
  Option<S> o;
  o.name = name;
  o.metavar = metavar;
  o.kind = ValueKind::Word;
  o.help = help;
  o.set = [field, choices](S& s, const OptionValue& v, const OptionContext&) {
    std::vector<std::string> words;
    for (const auto& [word, value] : choices) {
      if (word == v.word) {
        field(s) = value;
        return;
      }
      words.push_back(word);
    }
    throw std::invalid_argument(v.written + " is not " + alternatives(words));
  };
  o.show = [field, choices](const S& s) {
    for (const auto& [word, value] : choices)
      if (field(s) == value)
        return word;
    return std::string();
  };
  return o;
}

/** The choices of an enum whose names a toString() of its namespace gives, in \a order. */
template <typename E>
std::vector<std::pair<std::string, E>>
namedChoices(const std::vector<E>& order)
{
  std::vector<std::pair<std::string, E>> choices;
  for (const E e : order)
    choices.emplace_back(toString(e), e);
  return choices;
}

/** "A,B" of two values as the help prints them. */
template <typename T>
std::string
shownPair(T a, T b)
{
  if constexpr (std::is_floating_point_v<T>)
    return compactNumber(static_cast<float>(a)) + "," + compactNumber(static_cast<float>(b));
  else
    return std::to_string(a) + "," + std::to_string(b);
}

/** "x,y,z" as the help prints it. */
inline std::string
shownVector(const Eigen::Vector3f& v)
{
  return compactNumber(v.x()) + "," + compactNumber(v.y()) + "," + compactNumber(v.z());
}

// ---------------------------------------------------------------------------- values

/** \a text read as a value of \a o's kind (\a o.words taken as they are).
 * \throws std::invalid_argument saying what is wrong, after "option --NAME: ". */
template <typename S>
OptionValue
readOptionValue(const Option<S>& o, const std::string& text)
{
  OptionValue v;
  v.written = o.kind == ValueKind::Word ? "'" + text + "'" : text;
  if (o.kind == ValueKind::Word ||
      std::find(o.words.begin(), o.words.end(), text) != o.words.end()) {
    v.word = text;
    if (o.kind != ValueKind::Word)
      v.written = "'" + text + "'";
    return v;
  }
  std::istringstream in(text);
  char comma1 = 0, comma2 = 0;
  switch (o.kind) {
  case ValueKind::Integer: {
    const std::size_t first = !text.empty() && text[0] == '-' ? 1 : 0;
    if (text.size() == first || text.find_first_not_of("0123456789", first) != std::string::npos)
      throw std::invalid_argument("'" + text + "' is not an integer");
    errno = 0;
    v.integer = std::strtoll(text.c_str(), nullptr, 10);
    v.overflow = errno == ERANGE;
    break;
  }
  case ValueKind::Number: {
    char* end = nullptr;
    errno = 0;
    v.number = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !std::isfinite(v.number) || errno == ERANGE)
      throw std::invalid_argument("'" + text + "' is not a number");
    break;
  }
  case ValueKind::Pair:
    if (!(in >> v.pair.first >> comma1 >> v.pair.second) || comma1 != ',' || !in.eof() ||
        !std::isfinite(v.pair.first) || !std::isfinite(v.pair.second))
      throw std::invalid_argument("expected A,B, got '" + text + "'");
    break;
  case ValueKind::Vector3:
    if (!(in >> v.vector.x() >> comma1 >> v.vector.y() >> comma2 >> v.vector.z()) ||
        comma1 != ',' || comma2 != ',' || !v.vector.allFinite())
      throw std::invalid_argument("expected x,y,z, got '" + text + "'");
    break;
  default:
    break;
  }
  return v;
}

/** A value given for an option of a table, and how the user spelled the option (--k, k). */
template <typename S> struct GivenOption {
  const Option<S>* option;
  std::string spelling;
  OptionValue value;
};

/** Applies \a given to \a s: options that exclude each other are refused, then the options are
 * set in the table's order (those marked first before the others), and \a s is validated after
 * each, so that a complaint names the option that caused it: "option --NAME: VALUE RULE"
 * (Python: "NAME: VALUE RULE"), or validate()'s whole message when it has no rule.
 * \throws std::invalid_argument. */
template <typename S>
void
applyOptions(const SettingsTable<S>& table, const std::vector<GivenOption<S>>& given,
             const Vocabulary& say, S& s)
{
  const auto find = [&given](const std::string& name) -> const GivenOption<S>* {
    for (const auto& g : given)
      if (g.option->name == name)
        return &g;
    return nullptr;
  };
  for (const auto& e : table.exclusive)
    if (find(e.a) && find(e.b))
      throw std::invalid_argument(!e.why.empty() ? e.why
                                                 : say.option(e.a) + " and " + say.option(e.b) +
                                                     " exclude each other");
  OptionContext context{say, [&find](const std::string& name) -> const OptionValue* {
                          const GivenOption<S>* g = find(name);
                          return g ? &g->value : nullptr;
                        }};
  for (const bool first : {true, false})
    for (const auto& o : table.options) {
      const GivenOption<S>* g = o.first == first ? find(o.name) : nullptr;
      if (!g)
        continue;
      const std::string where = (say.python ? "" : "option ") + g->spelling + ": ";
      try {
        o.set(s, g->value, context);
      }
      catch (const std::invalid_argument& e) {
        throw std::invalid_argument(where + e.what());
      }
      std::string rule;
      const std::string why = table.validate(s, &rule);
      if (!why.empty())
        throw std::invalid_argument(where + (rule.empty() ? why : g->value.written + " " + rule));
    }
}

/** The options of \a table given on a command line. \throws std::invalid_argument. */
template <typename S>
std::vector<GivenOption<S>>
givenOptions(const SettingsTable<S>& table, const Arguments& args)
{
  std::vector<GivenOption<S>> given;
  for (const auto& o : table.options) {
    const std::string name = "--" + o.name;
    if (!args.has(name))
      continue;
    GivenOption<S> g{&o, args.spelling(name), {}};
    if (o.kind != ValueKind::Switch) {
      try {
        g.value = readOptionValue(o, args.text(name, ""));
      }
      catch (const std::invalid_argument& e) {
        throw std::invalid_argument("option " + g.spelling + ": " + e.what());
      }
    }
    given.push_back(std::move(g));
  }
  return given;
}

/** The options of \a table given on a command line, applied to \a s (see applyOptions). */
template <typename S>
void
applyOptions(const SettingsTable<S>& table, const Arguments& args, S& s)
{
  applyOptions(table, givenOptions(table, args), Vocabulary{}, s);
}

/** Names for Arguments: the options of \a table that take a value ("--name"). */
template <typename S>
std::set<std::string>
valueOptions(const SettingsTable<S>& table)
{
  std::set<std::string> names;
  for (const auto& o : table.options)
    if (o.kind != ValueKind::Switch)
      names.insert("--" + o.name);
  return names;
}

/** Names for Arguments: the switches of \a table. */
template <typename S>
std::set<std::string>
switches(const SettingsTable<S>& table)
{
  std::set<std::string> names;
  for (const auto& o : table.options)
    if (o.kind == ValueKind::Switch)
      names.insert("--" + o.name);
  return names;
}

/** Names for Arguments: the old spellings of \a table's options. */
template <typename S>
Arguments::Aliases
aliases(const SettingsTable<S>& table)
{
  Arguments::Aliases names;
  for (const auto& o : table.options)
    if (!o.alias.empty())
      names["--" + o.alias] = "--" + o.name;
  return names;
}

/** The help lines of \a table's options, their defaults those of \a defaults. */
template <typename S>
std::string
helpText(const SettingsTable<S>& table, const S& defaults)
{
  std::string out;
  const std::string indent(table.column, ' ');
  for (const auto& o : table.options) {
    if (o.hidden)
      continue;
    std::string head = "  --" + o.name + (o.metavar.empty() ? "" : " " + o.metavar);
    head += head.size() < table.column ? std::string(table.column - head.size(), ' ') : "  ";
    std::string text = o.help;
    if (const auto at = text.find("{}"); at != std::string::npos && o.show)
      text.replace(at, 2, o.show(defaults));
    for (std::size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at + 1))
      text.insert(at + 1, indent);
    out += o.heading + head + text + "\n";
  }
  return out;
}

} // namespace facyl_cli
