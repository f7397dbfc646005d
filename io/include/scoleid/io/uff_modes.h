#pragma once
// Measured modes from a Universal File's datasets 55 (docs/data.md §1.3): the normal modes an
// experimental modal analysis exported, as the product's measured-modes data (modal_data.h).
//
// A dataset 55 carries a mode's frequency (and, for normal modes, its viscous damping ratio; for
// complex modes its eigenvalue λ, frequency |λ|/2π, damping ratio −Re λ/|λ|) and its shape at
// nodes, 3 or 6 values per node (X Y Z [RX RY RZ]) or 1 (scalar). Nothing in the file says how
// well these are known, so the standard deviations come from the user:
//   frequency_std    relative standard deviation of every frequency (σ_f = frequency_std · f)
//   damping_std      absolute standard deviation of every damping ratio (0: no damping data)
//   shape_std        standard deviation of each component of the unit-normalised shape
//   stations         scenario sensor ← "<node><sign><axis>", axis X Y Z RX RY RZ ("12+Y",
//                    "7-RZ"); a scalar node is "<node>". The sign turns the node's axis into the
//                    sensor's direction.
// Modes are taken in order of frequency and labelled 1, 2, ...; only structural modes of
// analysis types 2 (normal), 3 and 7 (complex) are modes. A complex shape is turned by the phase
// of its largest component and its real part kept (the normal mode nearest to it, for light
// damping).
#include <string>
#include <utility>
#include <vector>

#include "scoleid/io/modal_data.h"
#include "scoleid/io/uff.h"

namespace scoleid::io {

struct UffModesOptions {
  double frequency_std = 0.0;  // relative, > 0
  double damping_std = 0.0;    // absolute, >= 0 (0: damping not used)
  double shape_std = 0.0;      // > 0 when there are stations
  std::vector<std::pair<std::string, std::string>> stations;  // sensor name, "<node><sign><axis>"
  std::string source;          // where these options were given, for messages
};

// The modes of `file`. InputError naming the file (and record) or the option for: no mode in the
// file, a station naming a node or an axis the file's shapes lack, a malformed station, missing
// standard deviations.
ModalData modal_data_from_uff(const uff::File& file, const UffModesOptions& options);

}  // namespace scoleid::io
