#pragma once
// The parts of the campaign on issue 32's commands (sim, strip, export-hylc, fit-splines,
// accuracy, study), beside issue 11's parts A-D in harden_campaign.cpp.
#include <filesystem>
#include <random>
#include <string>

namespace campaign {

// An empty folder `dir` holding a small synthetic dataset d.h5 and a 2-epoch model m.h5 of two
// terms (harden_campaign.cpp).
std::filesystem::path fresh_model_dir(const std::filesystem::path& dir);

struct NewPartsOptions {
  std::string strip_pattern;  // small real strips (F, G): the paper's stocktiny, as the tests use
  std::string check_pattern;  // option checks of strip, accuracy, study (E, F): one that holds at any size
  int scene_mutants = 120, hylc_mutants = 60, baked_mutants = 40;
  int sim_kills = 8, strip_kills = 8, accuracy_kills = 6;
};

// E. Refusals of the new commands: hostile option values, scene-file and HYLC-JSON mutants,
//    FIFO inputs, corrupted bytes of a baked file through eval (campaign_new_refusals.cpp).
void part_e_refusals(const std::filesystem::path& work, const NewPartsOptions& o, std::mt19937_64& rng);
// F. Outputs: -o naming a file, a FIFO, /dev/null, /proc/...; inputs as outputs; a failed run
//    leaves the previous output; stale outputs of earlier runs (campaign_new_runs.cpp).
void part_f_outputs(const std::filesystem::path& work, const NewPartsOptions& o);
// G. Kills of sim, strip and accuracy at random moments; the rerun must restart or resume
//    cleanly to the uninterrupted run's result (campaign_new_runs.cpp).
void part_g_kills(const std::filesystem::path& work, const NewPartsOptions& o, std::mt19937_64& rng);

}  // namespace campaign
