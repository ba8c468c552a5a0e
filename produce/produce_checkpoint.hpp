#pragma once
// The checkpoint of a running `produce` (DATASET.h5.partial): every finished node with the
// equilibrium state it ended in, so that a resumed run continues exactly as an uninterrupted
// one (issue 11): a child of a resumed node warm-starts, with the continuation predictor, from
// the very bits its parent ended with, and the dataset comes out bit for bit the same.
//
// Layout (docs/conventions.md section 10):
//   line 1  "yarnhom-produce-checkpoint 3 <fingerprint of the run>\n"
//   line 2  "rest <Psi0 as a hex float> <FNV-1a 64 of the rest state, 16 hex digits>\n"
//   then records, appended and flushed one per finished node:
//     "YREC", uint64 payload size, payload, uint64 FNV-1a 64 of the payload
// in the machine's byte order (a file to resume on the machine that wrote it). A kill can only
// cut the last record: reading stops at the first record that is incomplete or fails its
// checksum, and a resumed run truncates the file there before appending.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "yarn/rve/rve.hpp"

namespace yarnhom::yarn {

inline constexpr int kCheckpointVersion = 3;

// One finished node. `state` and `sensitivity` are present for a converged node of a warm
// started run (what its children start from); failures carry none (they are solved again).
struct CheckpointRecord {
  int term = 0, index = 0, iterations = 0;
  double seconds = 0, cpu_seconds = 0;
  std::string status;
  double psi = 0;
  Strain grad = Strain::Zero();
  bool has_state = false;
  RveState state;
  std::vector<Eigen::VectorXd> sensitivity;  // du/dt per term axis (SolveReport::sensitivity)
  double min_distance = 0;                    // closest centrelines along its certified path (m)
  std::uintmax_t offset = 0;                  // where the record starts in the file (when read)
};

// A record as bytes (the checkpoint's record payload, without its frame and checksum), and
// back: also what produce's MPI ranks send each other (produce/produce_cluster.cpp). decode
// throws std::runtime_error for bytes that are not one whole record.
std::string encode_record(const CheckpointRecord& r, const RveState& rest);
CheckpointRecord decode_record(const std::string& bytes, const RveState& rest);

// Identity of the rest state a run starts from: its Psi0 bits and a hash of its unknowns and
// frames. A checkpoint whose rest differs (another build, another thread count in the rest
// relaxation) cannot be continued bit for bit.
std::string rest_signature(double psi0, const RveState& rest);

struct CheckpointContents {
  bool empty = true;        // no file, an empty one, or one cut inside its header: start fresh
  std::vector<CheckpointRecord> records;
  std::uintmax_t valid_bytes = 0;    // length of the header and the whole records
  std::uintmax_t dropped_bytes = 0;  // after them: a record cut by a kill
};

// Reads a checkpoint of the run with this fingerprint and rest signature: every whole record,
// checked, without its state (has_state says whether it has one; read_checkpoint_state reads
// it when needed, so that memory holds only the states still to be continued from). Throws
// FileError naming the file for a file of another format, of the older text format (2: samples
// without their states, which cannot be resumed exactly), of another run, or of another rest
// state. `rest` is the reference for the frames and vertex count.
CheckpointContents read_checkpoint(const std::string& path, const std::string& fingerprint,
                                   const std::string& rest_sig, const RveState& rest);

// The state and sensitivities of a record returned by read_checkpoint (FileError if the file
// no longer holds it).
void read_checkpoint_state(const std::string& path, const RveState& rest, CheckpointRecord& r);

// Starts a fresh checkpoint (header only) or reopens one for appending after its last whole
// record (the cut tail is removed first). Throws FileError naming the file.
std::FILE* open_checkpoint(const std::string& path, const std::string& fingerprint, const std::string& rest_sig,
                           const CheckpointContents* resume);

// Appends one record and flushes it. `rest` as for read_checkpoint.
void append_checkpoint(std::FILE* f, const std::string& path, const CheckpointRecord& r, const RveState& rest);

}  // namespace yarnhom::yarn
