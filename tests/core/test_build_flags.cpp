// Every translation unit of the project is compiled for one target: the same -m flags (the
// ISA: -march=native when YARNHOM_NATIVE), the same floating-point model and the same ABI
// defines (EIGEN_*, _GLIBCXX_*), whether g++ compiles it (.cpp) or nvcc's host pass does (.cu,
// through -Xcompiler); and no .cu file includes Eigen. (That nvcc's host compiler is the C++
// compiler, and sees the same ISA macros, tests/cuda/test_host_isa.cpp checks at run time.) Read from this build's compile_commands.json (CMakeLists.txt exports it).
// Code compiled for two targets and linked into one program breaks the one-definition rule,
// silently (docs/layout.md, "Compiler flags").
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// Splits a compile command as a POSIX shell would (quotes and backslash escapes).
std::vector<std::string> shell_split(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  bool have = false;
  char quote = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (quote) {
      if (c == quote) {
        quote = 0;
      } else if (c == '\\' && quote == '"' && i + 1 < s.size()) {
        cur += s[++i];
      } else {
        cur += c;
      }
    } else if (c == '\'' || c == '"') {
      quote = c, have = true;
    } else if (c == '\\' && i + 1 < s.size()) {
      cur += s[++i], have = true;
    } else if (c == ' ' || c == '\t' || c == '\n') {
      if (have) out.push_back(cur);
      cur.clear(), have = false;
    } else {
      cur += c, have = true;
    }
  }
  if (have) out.push_back(cur);
  return out;
}

struct Unit {
  std::string file, directory;
  bool cuda = false;
  std::vector<std::string> args;
};

// What decides the code a translation unit's host code compiles to, beyond its source: the
// target flags (-m...), the floating-point model, and the defines that change layouts or
// inline code (Eigen's, libstdc++'s).
struct Target {
  std::set<std::string> flags;
};

bool fp_model_flag(const std::string& f) {
  return f == "-ffast-math" || f == "-Ofast" || f.rfind("-ffp-contract", 0) == 0 ||
         f == "-funsafe-math-optimizations" || f == "-fassociative-math" || f == "-fno-math-errno" ||
         f == "-ffinite-math-only" || f == "-fno-signed-zeros" || f == "-freciprocal-math";
}

bool abi_define(const std::string& d) {  // d without the -D
  return d.rfind("EIGEN_", 0) == 0 || d.rfind("_GLIBCXX_", 0) == 0;
}

void add_host_flag(Target& t, const std::string& f) {
  if (f.rfind("-m", 0) == 0 || fp_model_flag(f)) t.flags.insert(f);
}

Target target_of(const Unit& u) {
  Target t;
  const auto& a = u.args;
  for (size_t i = 1; i < a.size(); ++i) {
    const std::string& f = a[i];
    if (f.rfind("-D", 0) == 0) {
      const std::string d = f.size() > 2 ? f.substr(2) : (i + 1 < a.size() ? a[i + 1] : "");
      if (abi_define(d)) t.flags.insert("-D" + d);
      continue;
    }
    if (!u.cuda) {
      add_host_flag(t, f);
      continue;
    }
    // nvcc: -Xcompiler=a,b / -Xcompiler a,b / --compiler-options ... go to the host compiler;
    // so does any unknown flag under -forward-unknown-to-host-compiler (CMake passes it).
    std::string host;
    for (const std::string opt : {"-Xcompiler", "--compiler-options"}) {
      if (f == opt && i + 1 < a.size()) host = a[++i];
      else if (f.rfind(opt + "=", 0) == 0) host = f.substr(opt.size() + 1);
    }
    if (!host.empty()) {
      std::stringstream ss(host);
      for (std::string part; std::getline(ss, part, ',');) add_host_flag(t, part);
      continue;
    }
    if (f.rfind("-m", 0) == 0 && f != "-m64") add_host_flag(t, f);  // forwarded to the host compiler
  }
  return t;
}

std::string show(const std::set<std::string>& s) {
  std::string r;
  for (const auto& f : s) r += (r.empty() ? "" : " ") + f;
  return r.empty() ? "(none)" : r;
}

std::vector<Unit> project_units() {
  const fs::path path = fs::path(YARNHOM_BINARY_DIR) / "compile_commands.json";
  std::vector<Unit> units;
  std::ifstream in(path);
  if (!in) return units;
  const nlohmann::json j = nlohmann::json::parse(in);
  const std::string src = fs::weakly_canonical(YARNHOM_SOURCE_DIR).string() + "/";
  for (const auto& e : j) {
    Unit u;
    u.file = fs::weakly_canonical(e.at("file").get<std::string>()).string();
    if (u.file.rfind(src, 0) != 0) continue;  // not ours (none today)
    u.directory = e.value("directory", "");
    u.cuda = fs::path(u.file).extension() == ".cu";
    if (e.contains("arguments")) {
      u.args = e.at("arguments").get<std::vector<std::string>>();
    } else {
      u.args = shell_split(e.at("command").get<std::string>());
    }
    if (!u.args.empty()) units.push_back(std::move(u));
  }
  return units;
}

#define REQUIRE_COMPILE_COMMANDS(units)                                                      \
  if ((units).empty())                                                                       \
  GTEST_SKIP() << "no compile_commands.json in " YARNHOM_BINARY_DIR                          \
               << " (a CMake generator that does not write it)"

}  // namespace

TEST(BuildFlags, EveryTranslationUnitTargetsTheSameIsa) {
  const std::vector<Unit> units = project_units();
  REQUIRE_COMPILE_COMMANDS(units);
  // The reference: the first .cpp file (core/ and friends), compiled by the C++ compiler.
  const Unit* ref = nullptr;
  for (const auto& u : units) {
    if (!u.cuda) {
      ref = &u;
      break;
    }
  }
  ASSERT_NE(ref, nullptr);
  const Target want = target_of(*ref);
#if YARNHOM_NATIVE_BUILD
  EXPECT_TRUE(want.flags.count("-march=native")) << ref->file << ": " << show(want.flags);
#else
  for (const auto& f : want.flags) EXPECT_NE(f.rfind("-march=", 0), 0u) << "YARNHOM_NATIVE=OFF yet " << f;
#endif
  int cu = 0, cpp = 0;
  for (const auto& u : units) {
    const Target t = target_of(u);
    (u.cuda ? cu : cpp)++;
    EXPECT_EQ(show(t.flags), show(want.flags))
        << u.file << (u.cuda ? " (nvcc's host pass)" : "") << " is compiled for another target than "
        << ref->file;
  }
#if YARNHOM_CUDA_BUILD
  EXPECT_GT(cu, 0) << "a CUDA build without .cu files in compile_commands.json";
#else
  EXPECT_EQ(cu, 0);
#endif
  EXPECT_GT(cpp, 100);
  std::printf("%d .cpp and %d .cu translation units, all with %s\n", cpp, cu, show(want.flags).c_str());
}

// nvcc compiles Eigen's host code unvectorized (Eigen turns its SIMD off under __CUDACC__,
// whatever -march says), so a .cu file that instantiated Eigen would still put a second build
// of Eigen's templates beside the .cpp files' one. The .cu files include none of it: their
// dependencies, as nvcc lists them (-M), hold no Eigen header.
TEST(BuildFlags, NoCudaTranslationUnitIncludesEigen) {
  const std::vector<Unit> units = project_units();
  REQUIRE_COMPILE_COMMANDS(units);
  int checked = 0;
  for (const auto& u : units) {
    if (!u.cuda) continue;
    // The compile command with -c FILE -o OBJ turned into -M FILE.
    std::string cmd = "cd '" + u.directory + "' &&";
    for (size_t i = 0; i < u.args.size(); ++i) {
      if (u.args[i] == "-o" || u.args[i] == "-MF" || u.args[i] == "-MT") {
        ++i;
        continue;
      }
      if (u.args[i] == "-c" || u.args[i] == "-MD") continue;
      cmd += " '" + u.args[i] + "'";
    }
    cmd += " -M 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[4096];
    for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    const int rc = ::pclose(p);
    ASSERT_EQ(rc, 0) << cmd << "\n" << out;
    EXPECT_EQ(out.find("/Eigen/"), std::string::npos) << u.file << " includes Eigen:\n" << out;
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no .cu files in this build (YARNHOM_CUDA off or no nvcc)";
}
