#pragma once
// What the commands print around their work: durations, whether stderr is a terminal (progress
// redrawn in place or a line now and then), and the preparation of an output file before any
// work (refused when it must not be written; temporaries of killed runs removed, saying so).
#include <string>
#include <vector>

namespace yarnhom {

// "12.3s", "4m05s", "2h07m".
std::string format_seconds(double s);

bool stderr_is_tty();

// Before any work: refuses an output that must not be written (core/file_checks.hpp: a folder,
// a device, a FIFO, an input of the command, an uncreatable path) and removes the temporaries
// that killed runs left beside it, saying so on stderr. Returns the file that will be written
// (the target of a symbolic link).
std::string prepare_output(const std::string& path, const std::vector<std::string>& inputs,
                           const std::string& option = "-o");

// An output folder before work is written into it (the -o of sim and strip): refused as
// check_output_folder refuses it (a file, a FIFO, a device, /proc/..., uncreatable), created
// with its missing parents, rid of the temporaries of killed runs in it and in `subfolders`
// (created too), and each of `files` (names relative to it) checked as check_output_file
// checks an output against `inputs`. Every command with a folder output calls this one.
void prepare_output_folder(const std::string& folder, const std::vector<std::string>& subfolders,
                           const std::vector<std::string>& files, const std::vector<std::string>& inputs,
                           const std::string& option = "-o");

// Removes, saying so, the temporaries of killed runs (AtomicOutput's "FILE.partial-PID") found
// directly in `folder` whose processes no longer run.
void remove_stale_temporaries_in(const std::string& folder);

}  // namespace yarnhom
