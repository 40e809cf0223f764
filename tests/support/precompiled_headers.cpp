// The unit that builds the tests' precompiled headers (tests/CMakeLists.txt, SEXTANT_TEST_PCH); it
// compiles nothing of its own.
