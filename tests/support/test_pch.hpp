// The headers most test files include, precompiled once (tests/CMakeLists.txt, foxi_test_pch) and
// reused by every test program: GoogleTest and the standard headers cost about a quarter of a test
// file's compile time, and there are over a hundred test files (CI's 2-core budget). Only external,
// stable headers: a foxi header here would rebuild every test when it changes.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>
