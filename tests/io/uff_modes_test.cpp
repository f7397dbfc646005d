// Measured modes from a Universal File's datasets 55 (io/uff_modes.h), on a file exported by a
// modal-test program (pyuff's uff55_translation.uff: three normal modes at 10, 12 and 13 Hz,
// four nodes with X Y Z translations).
#include "scoleid/io/uff_modes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "scoleid/io/error.h"

using namespace scoleid::io;

namespace {
const std::string kFile = std::string(SCOLEID_TEST_DATA_DIR) + "/uff/uff55_translation.uff";

UffModesOptions options() {
  UffModesOptions o;
  o.frequency_std = 0.01;
  o.shape_std = 0.02;
  o.stations = {{"tip_x", "1+X"}, {"root_z", "4-Z"}};
  o.source = "modes.yaml";
  return o;
}

std::string error_of(const uff::File& f, const UffModesOptions& o) {
  try {
    modal_data_from_uff(f, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(UffModes, ModesFrequenciesAndShapesAtStations) {
  const uff::File f = uff::read_file(kFile);
  const ModalData d = modal_data_from_uff(f, options());
  ASSERT_EQ(d.modes.size(), 3u);
  EXPECT_EQ(d.stations, (std::vector<std::string>{"tip_x", "root_z"}));
  const double hz[] = {10.0, 12.0, 13.0};
  for (std::size_t m = 0; m < 3; ++m) {
    EXPECT_EQ(d.modes[m].label, static_cast<int>(m + 1));
    EXPECT_DOUBLE_EQ(d.modes[m].frequency_hz, hz[m]);
    EXPECT_DOUBLE_EQ(d.modes[m].frequency_std_hz, 0.01 * hz[m]);
    EXPECT_TRUE(std::isnan(d.modes[m].damping_ratio));  // no damping_std: damping not used
    EXPECT_DOUBLE_EQ(d.modes[m].shape_std, 0.02);
  }
  // The file's first mode: node 1 X = -1.46518, node 4 Z = 0.724863 (station 4-Z turns its sign).
  EXPECT_DOUBLE_EQ(d.modes[0].shape[0], -1.46518);
  EXPECT_DOUBLE_EQ(d.modes[0].shape[1], -0.724863);
  // Each value is the one the reader holds for that node and axis, sign applied.
  for (std::size_t m = 0; m < 3; ++m) {
    EXPECT_EQ(d.modes[m].shape[0], f.shapes[m].values[0][0]);
    EXPECT_EQ(d.modes[m].shape[1], -f.shapes[m].values[3][2]);
  }
}

TEST(UffModes, StationsAndDeviationsTheFileCannotGiveAreRefused) {
  const uff::File f = uff::read_file(kFile);
  UffModesOptions o = options();
  o.stations = {{"tip_x", "9+X"}};
  EXPECT_NE(error_of(f, o).find("has no node 9 (station 'tip_x')"), std::string::npos) << error_of(f, o);
  o.stations = {{"tip_x", "1+RX"}};
  EXPECT_NE(error_of(f, o).find("node 1 has 3 values, no axis for station 'tip_x'"), std::string::npos) << error_of(f, o);
  o.stations = {{"tip_x", "1*X"}};
  EXPECT_EQ(error_of(f, o), "modes.yaml: modes.stations.tip_x must be <node><+|-><X|Y|Z|RX|RY|RZ> (e.g. 12+Y), got '1*X'");
  o = options();
  o.frequency_std = 0;
  EXPECT_NE(error_of(f, o).find("modes.frequency_std must be a relative standard deviation in (0, 1)"), std::string::npos);
  o = options();
  o.shape_std = 0;
  EXPECT_NE(error_of(f, o).find("modes.shape_std must be > 0 when there are stations"), std::string::npos);
  // The file's normal modes state damping ratio 0: usable with a stated deviation.
  o = options();
  o.damping_std = 0.001;
  const ModalData d = modal_data_from_uff(f, o);
  EXPECT_TRUE(d.has_damping());
  EXPECT_EQ(d.modes[0].damping_ratio, f.shapes[0].damping_ratio);
}
