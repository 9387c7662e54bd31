// The translation unit that builds the test files' precompiled header
// (support/precompiled.h, tests/CMakeLists.txt); it has no code of its own.
