#pragma once
// The sizes a run may reach, checked before any work is done (validation.h, and the identifier's
// and the truth's own estimates of their storage). Every count a scenario or a command line can
// drive — samples, chain segments, FE elements, time steps, bytes of trajectory storage — is
// bounded here, so a typo (duration: 1e9, sample_interval: 1e-9, time_step: 1e-12) is refused
// with one line naming the field and the limit instead of hanging or exhausting memory.
#include <cstddef>

namespace scoleid::io::limits {

// Samples per record: floor(duration / sample_interval) + 1 (truth output, identifier data).
constexpr double kMaxSamples = 5.0e6;
// Values in one record (samples x columns): the data table and the predicted outputs.
constexpr double kMaxRecordValues = 1.0e8;
// Segments of a Simbody chain. The truth linearises the chain (a dense Jacobian of its
// 2 x (mobilities) states and its eigenvalues) to choose the integrator and its step.
constexpr int kMaxSegments = 1000;
// Finite elements of the identifier's mesh and of the mesh that synthesises data. Above 1000
// degrees of freedom the modal analyses (the step rule, the modes table, the spectral start) take
// the few modes they need from a sparse solver (identify/fe/lowest_modes.h): paper-beam-1 on 1024
// elements (its data on 2048) takes about 6 s, where dense eigenproblems took 160 s. The bound is
// accuracy now: any eigen solver's relative error in a beam's lowest frequency grows as N⁴
// (docs/theory.md §4.4), 10⁻⁵ at 1024 elements.
constexpr int kMaxElements = 1024;
constexpr int kMaxDataElements = 4096;
// Time steps of one trajectory (identifier or truth).
constexpr double kMaxSteps = 5.0e7;
// Bytes of trajectory storage an identification may hold at once (state, costate, sensitivities).
constexpr double kMaxTrajectoryBytes = 8.0 * 1024 * 1024 * 1024;
// Every number in a scenario: 0 or magnitude in [kMinMagnitude, kMaxMagnitude]. Wide enough for
// any consistent unit system (EI of 1e18 N mm^2, noise of 1e-12 m), narrow enough that products
// of a few such numbers stay far from overflow and underflow in double precision.
constexpr double kMaxMagnitude = 1.0e24;
constexpr double kMinMagnitude = 1.0e-24;
// Names of inputs, sensors and scenarios: characters [A-Za-z0-9_.-], first a letter, digit or
// '_', at most this long. They become CSV column headers, JSON keys, plot titles and directory
// names, so nothing in them may need quoting anywhere.
constexpr std::size_t kMaxNameLength = 64;

}  // namespace scoleid::io::limits
