// SCOLE built-in scenarios (DESIGN §4), slug-ft-s.
#include "scoleid/io/builtin.h"

namespace scoleid::io {

std::vector<BuiltinScenario> scole_builtin_scenarios() { return {}; }

}  // namespace scoleid::io
