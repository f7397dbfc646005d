#pragma once
// The campaign over MPI (campaign_mpi.cpp; built when CMake finds MPI). The caller checks first
// that the process was started by an MPI launcher.
#include <string>

#include "scoleid/crosscheck/campaign_runner.h"

namespace scoleid::crosscheck {

// Initialises MPI, runs the campaign file over MPI_COMM_WORLD (opt.out empty: run/campaign/<name>),
// finalises; returns this rank's exit code (every rank the same: 0, 1 a case failed, 2 bad input;
// an interrupt or a failure of the run aborts the job).
int run_campaign_mpi(const std::string& file, CampaignRunOptions opt);

}  // namespace scoleid::crosscheck
