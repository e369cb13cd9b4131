// Must not compile with -ffast-math (the "cmake: -ffast-math is refused" test).
#include <meshmotion/core/types.hpp>

int main() { return 0; }
