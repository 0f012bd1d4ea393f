// The object library that builds the libraries' shared precompiled header
// (cmake/puzzlecal.cmake, puzzlecal_library_pch_host); it holds no code.
