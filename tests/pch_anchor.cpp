// Anchor translation unit of the shared precompiled test header (tests/CMakeLists.txt).
