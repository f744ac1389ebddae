#include <cstdio>
int main() {
  std::puts("uh: command-line program of UnrealHaptics (subcommands land with their modules)");
  return 0;
}
