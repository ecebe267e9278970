/*
 * facyl: small helpers shared by the command-line tools (strict option parsing, -h and
 * --version, outputs that never replace an input, JSON).
 */
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

namespace facyl_cli {

/** \a v as the shortest decimal that reads back as it for help texts (0.5, not 0.500000). */
inline std::string
compactNumber(float v)
{
  char text[32];
  std::snprintf(text, sizeof text, "%g", static_cast<double>(v));
  return text;
}

/** The largest seed an option accepts (seeds are read as signed 64-bit integers). */
constexpr long long kMaxSeed = std::numeric_limits<long long>::max();

/** Options "--name value" or "--name=value" and switches "--name"; everything else is a
 * positional argument. Unknown options, malformed values and an option given twice are errors
 * (std::invalid_argument), never ignored. \a aliases maps old spellings to the current name
 * (an option is read by its current name; messages use the spelling the user typed). */
class Arguments {
public:
  using Aliases = std::map<std::string, std::string>;

  Arguments(int argc, char** argv, const std::set<std::string>& with_value,
            const std::set<std::string>& switches, const Aliases& aliases = {})
      : Arguments(std::vector<std::string>(argv + std::min(argc, 1), argv + argc), with_value,
                  switches, aliases)
  {
  }
  /** The same from a list of words (without the program's name). */
  Arguments(const std::vector<std::string>& words, const std::set<std::string>& with_value,
            const std::set<std::string>& switches, const Aliases& aliases = {})
  {
    for (std::size_t i = 0; i < words.size(); ++i) {
      const std::string& a = words[i];
      if (!(a.size() > 1 && a[0] == '-' &&
            !(std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.'))) {
        positional_.push_back(a);
        continue;
      }
      const std::size_t eq = a.find('=');
      const std::string typed = a.substr(0, eq);
      const auto alias = aliases.find(typed);
      const std::string name = alias == aliases.end() ? typed : alias->second;
      if (spelling_.count(name))
        throw std::invalid_argument(
          "option " + typed + " given twice" +
          (spelling_[name] != typed ? " (as " + spelling_[name] + ")" : ""));
      if (switches.count(name)) {
        if (eq != std::string::npos)
          throw std::invalid_argument("option " + typed + " takes no value");
        switches_.insert(name);
        spelling_[name] = typed;
        continue;
      }
      if (!with_value.count(name))
        throw std::invalid_argument("unknown option " + typed + " (see -h)");
      if (eq != std::string::npos)
        values_[name] = a.substr(eq + 1);
      else if (i + 1 >= words.size())
        throw std::invalid_argument("option " + typed + " needs a value");
      else
        values_[name] = words[++i];
      spelling_[name] = typed;
    }
  }
  bool has(const std::string& s) const
  {
    return switches_.count(s) > 0 || values_.count(s) > 0;
  }
  /** How the user spelled option \a name (its name when not given). */
  std::string spelling(const std::string& name) const
  {
    const auto it = spelling_.find(name);
    return it == spelling_.end() ? name : it->second;
  }
  const std::vector<std::string>& positional() const
  {
    return positional_;
  }
  std::string text(const std::string& name, const std::string& fallback) const
  {
    const auto it = values_.find(name);
    return it == values_.end() ? fallback : it->second;
  }
  /** The value of \a name as a finite number in [\a min_value, \a max_value]. */
  double number(const std::string& name, double fallback,
                double min_value = -std::numeric_limits<double>::max(),
                double max_value = std::numeric_limits<double>::max()) const
  {
    const auto it = values_.find(name);
    if (it == values_.end())
      return fallback;
    const std::string option = spelling(name);
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(it->second.c_str(), &end);
    if (end == it->second.c_str() || *end != '\0' || !std::isfinite(v) || errno == ERANGE)
      throw std::invalid_argument("option " + option + ": '" + it->second + "' is not a number");
    if (v < min_value || v > max_value)
      throw std::invalid_argument("option " + option + ": " + it->second + " is not in [" +
                                  shortNumber(min_value) + ", " + shortNumber(max_value) + "]");
    return v;
  }
  /** The value of \a name as an integer in [\a min_value, \a max_value]: digits only (an
   * optional minus sign), no wrap-around, no saturation. */
  long long integer(const std::string& name, long long fallback, long long min_value,
                    long long max_value) const
  {
    const auto it = values_.find(name);
    if (it == values_.end())
      return fallback;
    const std::string option = spelling(name);
    const std::string& t = it->second;
    const std::size_t first = !t.empty() && t[0] == '-' ? 1 : 0;
    if (t.size() == first || t.find_first_not_of("0123456789", first) != std::string::npos)
      throw std::invalid_argument("option " + option + ": '" + t + "' is not an integer");
    errno = 0;
    const long long v = std::strtoll(t.c_str(), nullptr, 10);
    if (errno == ERANGE || v < min_value || v > max_value)
      throw std::invalid_argument("option " + option + ": " + t + " is not in [" +
                                  std::to_string(min_value) + ", " + std::to_string(max_value) +
                                  "]");
    return v;
  }
  Eigen::Vector3f vector3(const std::string& name, const Eigen::Vector3f& fallback) const
  {
    const auto it = values_.find(name);
    if (it == values_.end())
      return fallback;
    Eigen::Vector3f v;
    char comma1, comma2;
    std::istringstream in(it->second);
    if (!(in >> v.x() >> comma1 >> v.y() >> comma2 >> v.z()) || comma1 != ',' || comma2 != ',' ||
        !v.allFinite())
      throw std::invalid_argument("option " + spelling(name) + ": expected x,y,z, got '" +
                                  it->second + "'");
    return v;
  }

private:
  static std::string shortNumber(double v)
  {
    std::ostringstream s;
    s << v;
    return s.str();
  }
  std::map<std::string, std::string> values_;
  std::set<std::string> switches_;
  std::map<std::string, std::string> spelling_; ///< name -> as typed
  std::vector<std::string> positional_;
};

/** "A,B" option as two numbers (\a a, \a b when absent). */
inline std::pair<double, double>
pairOption(const Arguments& args, const std::string& name, double a, double b)
{
  const std::string text = args.text(name, "");
  if (text.empty())
    return {a, b};
  std::istringstream in(text);
  char comma = 0;
  if (!(in >> a >> comma >> b) || comma != ',' || !in.eof() || !std::isfinite(a) ||
      !std::isfinite(b))
    throw std::invalid_argument("option " + args.spelling(name) + ": expected A,B, got '" + text +
                                "'");
  return {a, b};
}

/** The union of option name sets. */
inline std::set<std::string>
joined(std::set<std::string> a, const std::set<std::string>& b)
{
  a.insert(b.begin(), b.end());
  return a;
}

/** True if -h or --help is among the arguments. */
inline bool
wantsHelp(int argc, char** argv)
{
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "-h" || std::string(argv[i]) == "--help")
      return true;
  return false;
}

#ifndef FACYL_VERSION
#define FACYL_VERSION "unknown"
#endif

/** The help lines every tool ends with. */
inline const char*
commonHelp()
{
  return "  -h, --help             this help\n"
         "  --version              facyl's version\n"
         "Options take their value as --name VALUE or --name=VALUE. Lengths are in metres.\n";
}

/** -h / --help (prints \a help) and --version, which every tool answers the same way.
 * \return the exit status when one of them was given (0), else -1: go on. */
template <typename PrintHelp>
int
standardOptions(int argc, char** argv, const char* tool, PrintHelp help)
{
  if (wantsHelp(argc, argv)) {
    help(argv[0]);
    return 0;
  }
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--version") {
      std::printf("%s (facyl) %s\n", tool, FACYL_VERSION);
      return 0;
    }
  return -1;
}

/** The opening every tool shares: -h/--help and --version (standardOptions), then \a parse,
 * which reads the options; a std::exception it throws is a usage error: "TOOL: what" on stderr
 * and exit status 2. \return -1 when the tool goes on, else the exit status to return now. */
template <typename PrintHelp, typename Parse>
int
startTool(int argc, char** argv, const char* tool, PrintHelp help, Parse&& parse)
{
  if (const int rc = standardOptions(argc, argv, tool, help); rc >= 0)
    return rc;
  try {
    parse();
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
    return 2;
  }
  return -1;
}

/** Progress of a long run on stderr ("TOOL: n/N, t s, about u s left", redrawn at most every
 * second) when stderr is a terminal and the run has more than one item; silent otherwise (logs
 * and pipes stay clean), and while the results go to that terminal too, unless \a quiet_stdout
 * says that nothing is printed there during the run. step() may be called from several
 * threads. */
class Progress {
public:
  Progress(const char* tool, std::size_t total, bool quiet_stdout = false)
      : tool_(tool)
      , total_(total)
      , shown_(total > 1 && isatty(fileno(stderr)) != 0 &&
               (quiet_stdout || isatty(fileno(stdout)) == 0))
      , start_(std::chrono::steady_clock::now())
      , last_(start_)
  {
  }
  ~Progress()
  {
    if (shown_ && drawn_)
      std::fprintf(stderr, "\n");
  }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /** \a n more items done. */
  void step(std::size_t n = 1)
  {
    if (!shown_)
      return;
    const std::lock_guard<std::mutex> lock(mutex_);
    done_ += n;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::seconds(1) && done_ < total_)
      return;
    last_ = now;
    drawn_ = true;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double left = done_ ? elapsed / static_cast<double>(done_) *
                                  static_cast<double>(total_ - std::min(done_, total_))
                              : 0.0;
    std::fprintf(stderr, "\r%s: %zu/%zu, %.0f s, about %.0f s left   ", tool_, done_, total_,
                 elapsed, left);
  }

private:
  const char* tool_;
  std::size_t total_, done_{0};
  bool shown_, drawn_{false};
  std::chrono::steady_clock::time_point start_, last_;
  std::mutex mutex_;
};

// ---- outputs: never over an input, never a file of another kind ----

/** True when \a a and \a b name the same file (the same inode when both exist, else the
 * same canonical path). */
inline bool
samePath(const std::filesystem::path& a, const std::filesystem::path& b)
{
  std::error_code ec;
  if (std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec)) {
    const bool same = std::filesystem::equivalent(a, b, ec);
    if (!ec)
      return same;
  }
  std::error_code ea, eb;
  const auto ca = std::filesystem::weakly_canonical(a, ea);
  const auto cb = std::filesystem::weakly_canonical(b, eb);
  return !ea && !eb ? ca == cb : a.lexically_normal() == b.lexically_normal();
}

/** The extension of \a path in lower case, with its dot ("" when none). */
inline std::string
lowerExtension(const std::string& path)
{
  std::string e = std::filesystem::path(path).extension().string();
  for (auto& c : e)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

/** Refuses an output file: \a path (given by \a option) must end in one of \a extensions
 * (a \a kind, e.g. "PNG image"), must not be a folder and must not be one of \a inputs.
 * \throws std::invalid_argument saying why (the tools exit 2 before writing anything). */
inline void
checkOutputFile(const std::string& option, const std::string& path,
                const std::vector<std::string>& extensions, const std::string& kind,
                const std::vector<std::string>& inputs)
{
  const std::string where = option.empty() ? "output " + path : option + " " + path;
  if (path.empty())
    throw std::invalid_argument(where + ": an empty path");
  const std::string ext = lowerExtension(path);
  if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) {
    std::string list;
    for (std::size_t k = 0; k < extensions.size(); ++k)
      list += (k ? (k + 1 == extensions.size() ? " or " : ", ") : "") + extensions[k];
    std::string hint;
    if (ext == ".pcd" || ext == ".ply")
      hint = " (" + path + " looks like a point cloud: was the output's name forgotten?)";
    throw std::invalid_argument(where + ": this output is a " + kind + "; give a path ending in " +
                                list + hint + ". Nothing was written.");
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw std::invalid_argument(where + ": is a folder; give a file name. Nothing was written.");
  for (const auto& in : inputs)
    if (!in.empty() && samePath(path, in))
      throw std::invalid_argument(where + ": is also an input (" + in +
                                  "); facyl never writes over its inputs. Nothing was written.");
}

/** Refuses an output folder whose generated files would replace an input: \a generated (file
 * names in \a dir, or a test on a file name in \a dir) must match none of \a inputs.
 * \throws std::invalid_argument. */
template <typename IsGenerated>
void
checkOutputFolder(const std::string& option, const std::string& dir, IsGenerated is_generated,
                  const std::vector<std::string>& inputs)
{
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw std::invalid_argument(option + " " + dir +
                                ": is a file, not a folder. Nothing was "
                                "written.");
  for (const auto& in : inputs) {
    if (in.empty())
      continue;
    const std::filesystem::path p(in);
    const std::filesystem::path parent = p.has_parent_path() ? p.parent_path() : ".";
    if (samePath(parent, dir) && is_generated(p.filename().string()))
      throw std::invalid_argument(option + " " + dir + ": it would write " +
                                  (std::filesystem::path(dir) / p.filename()).string() +
                                  ", which is an input; facyl never writes over its inputs. "
                                  "Nothing was written.");
  }
}

/** A warning about one input or output: on standard error, never in the exit status. */
inline void
warn(const char* tool, const std::string& what)
{
  std::fprintf(stderr, "%s: warning: %s\n", tool, what.c_str());
}

} // namespace facyl_cli
