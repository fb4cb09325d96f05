#include <iostream>
int main() { std::cout << "pegasus\n"; return 0; }
