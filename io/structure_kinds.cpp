#include "structure_kinds.h"

namespace scoleid::io {

const KindTable& kind_table(Structure kind) {
  switch (kind) {
    case Structure::Beam: return beam_kind();
    case Structure::Scole: return scole_kind();
    case Structure::Frame: return frame_kind();
  }
  return beam_kind();
}

std::vector<const KindTable*> kind_tables() { return {&beam_kind(), &scole_kind(), &frame_kind()}; }

ShapeSensor shape_sensor(const std::string& name, Site at, SensorKind kind, double s, std::vector<double> direction,
                         double scale) {
  ShapeSensor e;
  e.spec.name = name;
  e.spec.at = at;
  e.spec.kind = kind;
  e.spec.location = s;
  e.spec.direction = std::move(direction);
  e.scale = scale;
  return e;
}

std::vector<ShapeSensor> shape_sensors(const Scenario& sc, int count) { return kind_table(sc.structure).shape_sensors(sc, count); }

}  // namespace scoleid::io
