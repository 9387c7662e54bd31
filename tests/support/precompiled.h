// The headers nearly every test file includes, precompiled once per build
// tree and given to every test executable (tests/CMakeLists.txt,
// PROXIMA_TEST_PCH). Parsing GoogleTest, Eigen and proxima's public headers
// was about a third of each test file's compile under the sanitizers; a test
// file still includes what it uses, so it compiles without this header too.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "proxima/proxima.h"
#include "support/generators.h"
