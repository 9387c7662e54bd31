// Test main shared by every test executable: floating-point traps on, so an
// invalid operation (a NaN being made) or a division by zero anywhere in
// proxima stops the test at the faulting instruction instead of passing a
// NaN along silently.
#include <gtest/gtest.h>

#include <cfenv>

int main(int argc, char** argv) {
  feenableexcept(FE_INVALID | FE_DIVBYZERO);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
