#pragma once
// The processes of one run started by `mpirun` (Open MPI): who this process is among them, and
// byte messages between them. yarnhom is built with MPI when it is found (YARNHOM_MPI=AUTO|ON|
// OFF, like CUDA); without it, or when the program was not started by mpirun, the run is one
// process: size() is 1 and nothing here sends anything.
//
// Only `produce`, `accuracy` and the accuracy studies use more than one rank (docs/produce.md,
// "On a cluster"). MPI is initialized by main() only when the environment says
// that mpirun started the process, so a plain `yarnhom ...` never touches MPI.
#include <string>

namespace yarnhom::cluster {

// Whether this build has MPI at all.
bool compiled();

// MPI_Init when started by mpirun (Open MPI's, MPICH's or Slurm's PMI variables are set);
// nothing otherwise. finalize() at exit. Call once, from main, before any thread starts.
void init(int* argc, char*** argv);
void finalize();

int rank();  // 0 when not under MPI
int size();  // 1 when not under MPI
int node_size();  // the ranks on this rank's node (1 when not under MPI)
std::string host();  // this rank's node name
// "rank R on HOST" (for messages).
std::string where();

// Byte messages. receive() waits for a message with the tag from `source` (-1: any source);
// with poll_ms > 0 it waits by probing every poll_ms milliseconds, so that a rank that mostly
// waits (produce's coordinator) leaves its core to the ranks that work.
struct Message {
  int source = -1;
  int tag = 0;
  std::string bytes;
};
void send(int dest, int tag, const std::string& bytes);
Message receive(int source, int tag, int poll_ms = 0);
// A message with the tag from `source` (-1: any) if one has arrived; false at once otherwise.
bool try_receive(int source, int tag, Message& out);

// Ends every rank of the run (MPI_Abort) after printing `why` with this rank's name.
[[noreturn]] void abort(const std::string& why, int code = 1);

}  // namespace yarnhom::cluster
