// `stability --plot`: trace distance per update against log2(L/s), from every row of the
// stability CSV (so runs appended by earlier invocations are plotted too). One line per
// (distribution, dimension); each point is the mean trace distance of the rows whose
// log2_spread rounds to the same multiple of 0.5. Drawn by gnuplot's svg terminal; the script
// goes to gnuplot's stdin, with the data inline. gnuplot draws into a scratch file beside the
// picture; the picture then goes through AtomicOutputs (atomic_file.hpp) like every other
// output, so a failed plot leaves an earlier picture whole and nothing else behind.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <sys/wait.h>
#include <unistd.h>
#include <utility>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "dynmesh/errors.hpp"

namespace dynmesh::tool {
namespace {

using Kind = InputError::Kind;

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

bool on_path(const char* program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string_view rest(path);
  while (true) {
    const std::size_t colon = rest.find(':');
    const std::string dir(rest.substr(0, colon));
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/" + program;
    if (::access(candidate.c_str(), X_OK) == 0) return true;
    if (colon == std::string_view::npos) return false;
    rest.remove_prefix(colon + 1);
  }
}

// A gnuplot single-quoted string: only ' needs escaping, as ''.
std::string gp_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    out += c;
    if (c == '\'') out += '\'';
  }
  return out + "'";
}

struct Bucket {
  double sum = 0;
  std::size_t count = 0;
};

/// An empty file beside `path` (same directory, so a full or unwritable file system shows
/// up here already) for another program to write; removed when this goes out of scope.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& path) {
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? std::string{} : path.substr(0, slash + 1);
    name_ = dir + "." + path.substr(slash == std::string::npos ? 0 : slash + 1) + ".plot-XXXXXX";
    const int fd = ::mkstemp(name_.data());
    if (fd < 0)
      throw InputError(Kind::Io, std::string("cannot write output: cannot create a scratch file beside it: ") +
                                     std::strerror(errno),
                       path);
    ::close(fd);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  ~ScratchFile() { ::unlink(name_.c_str()); }
  const std::string& name() const noexcept { return name_; }

 private:
  std::string name_;
};

}  // namespace

void plot_stability_csv(const std::string& csv_path, const std::string& svg_path) {
  std::ifstream in(csv_path);
  if (!in) throw InputError(Kind::Io, std::string("cannot open file: ") + std::strerror(errno), csv_path);
  std::string line;
  std::size_t line_no = 0;
  int col_dist = -1, col_dim = -1, col_spread = -1, col_distance = -1;
  // (dist, dim) -> rounded log2 spread -> mean of trace_distance
  std::map<std::pair<std::string, std::string>, std::map<double, Bucket>> series;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::vector<std::string> f = split_csv_line(line);
    if (col_dist < 0) {
      for (std::size_t i = 0; i < f.size(); ++i) {
        const int c = static_cast<int>(i);
        if (f[i] == "dist") col_dist = c;
        if (f[i] == "dim") col_dim = c;
        if (f[i] == "log2_spread") col_spread = c;
        if (f[i] == "trace_distance") col_distance = c;
      }
      if (col_dist < 0 || col_dim < 0 || col_spread < 0 || col_distance < 0)
        throw InputError(Kind::Malformed, "not a stability CSV header", csv_path, line_no);
      continue;
    }
    const auto need = static_cast<std::size_t>(std::max({col_dist, col_dim, col_spread, col_distance}));
    if (f.size() <= need) throw InputError(Kind::Count, "too few fields", csv_path, line_no);
    char* end = nullptr;
    const double x = std::strtod(f[static_cast<std::size_t>(col_spread)].c_str(), &end);
    const double y = std::strtod(f[static_cast<std::size_t>(col_distance)].c_str(), &end);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;  // fewer than two points: no spread
    const std::pair key{f[static_cast<std::size_t>(col_dist)], f[static_cast<std::size_t>(col_dim)]};
    Bucket& b = series[key][std::round(x * 2) / 2];
    b.sum += y;
    ++b.count;
  }
  if (series.empty()) throw InputError(Kind::Empty, "no rows to plot", csv_path);
  if (!on_path("gnuplot"))
    throw InputError(Kind::Io, "--plot needs gnuplot, which is not on PATH (bash dev.sh deps installs it)");

  const ScratchFile drawn(svg_path);
  std::ostringstream gp;
  gp << "set terminal svg size 900,600 dynamic background rgb 'white' font 'Sans,12'\n"
     << "set output " << gp_quote(drawn.name()) << "\n"
     << "set title 'dynmesh stability: trace distance of single-point updates'\n"
     << "set xlabel 'log_2(L/s) of the point set (rounded to 0.5)'\n"
     << "set ylabel 'mean trace distance per update'\n"
     << "set grid\nset key top left noenhanced\nset yrange [0:*]\nset offsets 0.5, 0.5, 0, 0\n";
  // A single distinct x would make gnuplot warn about an empty x range: give it one.
  double xmin = HUGE_VAL, xmax = -HUGE_VAL;
  for (const auto& entry : series)
    for (const auto& bucket : entry.second) {
      xmin = std::min(xmin, bucket.first);
      xmax = std::max(xmax, bucket.first);
    }
  if (xmin == xmax) gp << "set xrange [" << xmin - 1 << ":" << xmax + 1 << "]\n";
  std::size_t k = 0;
  std::string plot = "plot ";
  for (const auto& [key, buckets] : series) {
    gp << "$D" << k << " << EOD\n";
    for (const auto& [x, b] : buckets) gp << x << ' ' << b.sum / static_cast<double>(b.count) << '\n';
    gp << "EOD\n";
    if (k) plot += ", \\\n     ";
    plot += "$D" + std::to_string(k) + " using 1:2 with linespoints pt 7 title " +
            gp_quote(key.first + " (" + key.second + "D)");
    ++k;
  }
  gp << plot << "\nset output\n";

  // gnuplot exiting early must not kill us with SIGPIPE.
  const auto old_handler = std::signal(SIGPIPE, SIG_IGN);
  FILE* pipe = ::popen("gnuplot", "w");
  if (!pipe) {
    std::signal(SIGPIPE, old_handler);
    throw InputError(Kind::Io, std::string("cannot run gnuplot: ") + std::strerror(errno));
  }
  const std::string script = gp.str();
  std::fwrite(script.data(), 1, script.size(), pipe);
  const int status = ::pclose(pipe);
  std::signal(SIGPIPE, old_handler);
  if (status != 0) {
    const int code = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    throw InputError(Kind::Io, "gnuplot failed (exit status " + std::to_string(code) + ") drawing the plot",
                     svg_path);
  }
  const std::string picture = AtomicOutputs::read_existing(drawn.name()).value_or(std::string{});
  if (picture.empty()) throw InputError(Kind::Io, "gnuplot did not write the plot", svg_path);
  AtomicOutputs out;
  out.add(svg_path, picture);
  out.commit();
}

}  // namespace dynmesh::tool
