# Doxygen input filter (docs/Doxyfile); it changes only what Doxygen reads, never the headers.
# C++14 digit separators out of numbers (50'000'000 -> 50000000): Sphinx's C++ parser cannot read them.
s/([0-9])'([0-9])/\1\2/g
s/([0-9])'([0-9])/\1\2/g
# Doxygen 1.9.4 reads a member named `local` with an `=` initializer as a member named `bool`; braces it reads.
s/\b(bool local) = ([a-z]+);/\1{\2};/
