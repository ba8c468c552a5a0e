#pragma once
// What the MPI command-line tests share (tests/tools/test_cli_produce_mpi.cpp, test_cli_study_mpi.cpp):
// the pattern they run, a private temporary folder, how to start mpirun on a test machine, and
// why they cannot run here. Only for the tools room's executable (YARNHOM_BINARY, YARNHOM_MPI_BUILD).
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/common/run_cli.hpp"

namespace yarnhom::test {

inline std::string mpi_stocktiny() { return std::string(YARNHOM_SOURCE_DIR) + "/../shared/patterns/stocktiny.pyp"; }

// A fresh folder PREFIX_PID_NAME under the temporary directory.
inline std::string mpi_tmpdir(const std::string& prefix, const char* name) {
  namespace fs = std::filesystem;
  fs::path d = fs::temp_directory_path() / (prefix + "_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

// mpirun as any user (CI runs as root), without the single-copy mechanism that containers'
// ptrace rules forbid, and with more ranks than cores; followed by the yarnhom binary.
inline std::string mpirun(int ranks) {
  return "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none "
         "mpirun --oversubscribe -np " + std::to_string(ranks) + " " + YARNHOM_BINARY;
}

// Why the MPI tests cannot run here with `ranks` processes, "" when they can. A machine where
// mpirun cannot start processes at all (a sandbox without shared memory or process tracing) is
// not a fault of the program: said, and skipped.
inline std::string mpi_skip_reason(int ranks) {
#if !YARNHOM_MPI_BUILD
  return "this yarnhom was built without MPI (libopenmpi-dev absent at configure time): the MPI tests skip";
#endif
  if (run_shell("command -v mpirun").status != 0) return "mpirun not found: the MPI tests skip";
  const std::string launcher = mpirun(ranks).substr(0, mpirun(ranks).rfind(' '));
  const auto probe = run_shell("timeout 60 env " + launcher + " true");
  if (probe.status != 0)
    return "mpirun cannot start " + std::to_string(ranks) + " processes here, the MPI tests skip: " + probe.out;
  if (!std::filesystem::exists(mpi_stocktiny())) return "shared pattern not found: " + mpi_stocktiny();
  return "";
}

// A whole file's bytes ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace yarnhom::test
