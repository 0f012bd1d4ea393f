// The target that builds the test binaries' shared precompiled header
// (cmake/puzzlecal.cmake, puzzlecal_test_pch_host); it runs no test.
int main() { return 0; }
