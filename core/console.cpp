#include "core/console.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/file_checks.hpp"

namespace yarnhom {

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  else
    std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
  return buf;
}

bool stderr_is_tty() { return ::isatty(2); }

namespace {
void say_removed(const std::vector<std::string>& removed) {
  for (const std::string& t : removed)
    std::fprintf(stderr, "yarnhom: removed %s, a temporary file left by an interrupted run\n", t.c_str());
}
}  // namespace

std::string prepare_output(const std::string& path, const std::vector<std::string>& inputs, const std::string& option) {
  const std::string target = check_output_file(path, inputs, option);
  say_removed(AtomicOutput::remove_stale_temporaries(path));
  return target;
}

void prepare_output_folder(const std::string& folder, const std::vector<std::string>& subfolders,
                           const std::vector<std::string>& files, const std::vector<std::string>& inputs,
                           const std::string& option) {
  const std::filesystem::path dir(folder);
  std::vector<std::filesystem::path> dirs = {dir};
  for (const std::string& sub : subfolders) dirs.push_back(dir / sub);
  for (const auto& d : dirs) {
    check_output_folder(d.string(), option);
    std::filesystem::create_directories(d);
  }
  for (const auto& d : dirs) remove_stale_temporaries_in(d.string());
  for (const std::string& f : files) check_output_file((dir / f).string(), inputs, option);
}

void remove_stale_temporaries_in(const std::string& folder) {
  for (const auto& e : std::filesystem::directory_iterator(folder)) {
    const std::string name = e.path().string();
    const size_t at = name.rfind(".partial-");
    if (at == std::string::npos) continue;
    say_removed(AtomicOutput::remove_stale_temporaries(name.substr(0, at)));
  }
}

}  // namespace yarnhom
