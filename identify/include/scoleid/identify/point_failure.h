#pragma once
// What an exception escaping a model evaluation at a trial point means (docs/theory.md §10.1a).
//
// The optimiser, the attempts and the assessment evaluate the model at points nobody chose: a
// trial step, a mirrored profile, a refined mesh. There the model may fail to exist — a mass
// block that is not positive definite, a parameter that left its range, an integrator that cannot
// advance — and that failure is a verdict on the point (the step is rejected, the candidate
// dropped): std::runtime_error from a solver, std::domain_error from the model. Anything else is
// not the point's fault and must reach the program, never become "does not explain the data": a
// defect (std::logic_error and its other kinds), an input the door should have refused
// (io::InputError), an interrupt (io::Interrupted), memory exhausted (std::bad_alloc).
//
// In a handler:   catch (const std::exception& e) { if (!point_failure(e)) throw; ...reject... }
#include <exception>
#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

inline bool point_failure(const std::exception& e) {
  if (dynamic_cast<const io::Interrupted*>(&e) || dynamic_cast<const io::InputError*>(&e)) return false;
  return dynamic_cast<const std::domain_error*>(&e) != nullptr || dynamic_cast<const std::runtime_error*>(&e) != nullptr;
}

// The same for an exception held as a pointer (from a worker thread, or a C solver's callback).
inline bool point_failure(const std::exception_ptr& p) {
  try {
    std::rethrow_exception(p);
  } catch (const std::exception& e) {
    return point_failure(e);
  } catch (...) {
    return false;
  }
}

}  // namespace scoleid::identify
