// Run at configure time (CMakeLists.txt, POINTILLIST_X86_64_V2): exits 0 when this CPU has
// what -march=x86-64-v2 lets the compiler use.
int main() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("sse3") && __builtin_cpu_supports("ssse3") &&
                 __builtin_cpu_supports("sse4.1") && __builtin_cpu_supports("sse4.2") &&
                 __builtin_cpu_supports("popcnt")
             ? 0
             : 1;
}
