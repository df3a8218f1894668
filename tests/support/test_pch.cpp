// Compiles tests/support/test_pch.hpp into the precompiled header the test programs reuse
// (tests/CMakeLists.txt); this file itself has nothing to build.
