#include "core/cluster.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <thread>
#include <vector>

#include <unistd.h>

#ifdef YARNHOM_WITH_MPI
// The C interface only (linked as MPI::MPI_C): not Open MPI's or MPICH's deprecated C++ bindings.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace yarnhom::cluster {
namespace {

[[maybe_unused]] bool g_active = false;  // MPI initialized by init() (only in a build with MPI)
int g_rank = 0, g_size = 1, g_node_size = 1;

// mpirun (Open MPI), mpiexec (MPICH, Hydra) and srun (Slurm's PMI) each set one of these.
bool started_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK", "SLURM_PMIX_MAPPING_SERV"})
    if (std::getenv(v)) return true;
  return false;
}

}  // namespace

#ifdef YARNHOM_WITH_MPI
bool compiled() { return true; }

void init(int* argc, char*** argv) {
  if (g_active || !started_by_mpirun()) return;
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  MPI_Comm node;  // the ranks that share this one's memory: its node
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &g_node_size);
  MPI_Comm_free(&node);
  g_active = true;
  // The launcher's variables were read by MPI_Init; a child process of this rank (a stage of
  // pipeline or accuracy, a plot script) must not take itself for a rank of this run.
  std::vector<std::string> names;
  for (char** e = environ; *e; ++e) {
    const std::string kv = *e;
    for (const char* prefix : {"OMPI_", "PMIX_", "PMI_"})
      if (kv.rfind(prefix, 0) == 0) names.push_back(kv.substr(0, kv.find('=')));
  }
  for (const auto& n : names) unsetenv(n.c_str());
  std::atexit(finalize);
}

void finalize() {
  if (!g_active) return;
  g_active = false;
  int done = 0;
  MPI_Finalized(&done);
  if (!done) MPI_Finalize();
}

std::string host() {
  if (!g_active) {
    char name[256] = {0};
    gethostname(name, sizeof name - 1);
    return name;
  }
  char name[MPI_MAX_PROCESSOR_NAME] = {0};
  int len = 0;
  MPI_Get_processor_name(name, &len);
  return std::string(name, len);
}

void send(int dest, int tag, const std::string& bytes) {
  if (!g_active) throw std::logic_error("cluster::send without MPI");
  if (bytes.size() > static_cast<size_t>(INT32_MAX)) throw std::length_error("cluster::send: message over 2 GiB");
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD);
}

Message receive(int source, int tag, int poll_ms) {
  if (!g_active) throw std::logic_error("cluster::receive without MPI");
  const int src = source < 0 ? MPI_ANY_SOURCE : source;
  const int tg = tag < 0 ? MPI_ANY_TAG : tag;
  MPI_Status st;
  if (poll_ms > 0) {
    for (int flag = 0;;) {
      MPI_Iprobe(src, tg, MPI_COMM_WORLD, &flag, &st);
      if (flag) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(poll_ms));
    }
  } else {
    MPI_Probe(src, tg, MPI_COMM_WORLD, &st);
  }
  int count = 0;
  MPI_Get_count(&st, MPI_BYTE, &count);
  Message m;
  m.source = st.MPI_SOURCE;
  m.tag = st.MPI_TAG;
  m.bytes.resize(count);
  MPI_Recv(m.bytes.data(), count, MPI_BYTE, m.source, m.tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return m;
}

bool try_receive(int source, int tag, Message& out) {
  if (!g_active) throw std::logic_error("cluster::try_receive without MPI");
  int flag = 0;
  MPI_Iprobe(source < 0 ? MPI_ANY_SOURCE : source, tag < 0 ? MPI_ANY_TAG : tag, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE);
  if (!flag) return false;
  out = receive(source, tag);
  return true;
}

void abort(const std::string& why, int code) {
  std::fprintf(stderr, "yarnhom: error: %s: %s\n", where().c_str(), why.c_str());
  std::fflush(stderr);
  if (g_active) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}
#else
bool compiled() { return false; }
void init(int*, char***) {
  if (started_by_mpirun() && std::getenv("OMPI_COMM_WORLD_SIZE") && std::atoi(std::getenv("OMPI_COMM_WORLD_SIZE")) > 1) {
    // Every rank would run the whole job alone and write the same files: refuse.
    std::fprintf(stderr, "yarnhom: error: started by mpirun with %s ranks, but this yarnhom was built without MPI "
                 "(install libopenmpi-dev and rebuild: the build finds it, docs/produce.md)\n",
                 std::getenv("OMPI_COMM_WORLD_SIZE"));
    std::exit(2);
  }
}
void finalize() {}
std::string host() {
  char name[256] = {0};
  gethostname(name, sizeof name - 1);
  return name;
}
void send(int, int, const std::string&) { throw std::logic_error("cluster::send: built without MPI"); }
Message receive(int, int, int) { throw std::logic_error("cluster::receive: built without MPI"); }
bool try_receive(int, int, Message&) { throw std::logic_error("cluster::try_receive: built without MPI"); }
void abort(const std::string& why, int code) {
  std::fprintf(stderr, "yarnhom: error: %s\n", why.c_str());
  std::exit(code);
}
#endif

int rank() { return g_rank; }
int size() { return g_size; }
int node_size() { return g_node_size; }
std::string where() { return "rank " + std::to_string(g_rank) + " on " + host(); }

}  // namespace yarnhom::cluster
