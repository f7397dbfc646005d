#pragma once
// What the cross-check's program tests share: the tests' common shell helpers (sh, slurp, scratch).
#include "common/cli_support.h"
