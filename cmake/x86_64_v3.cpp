// Run at configure time (CMakeLists.txt, POINTILLIST_X86_64_V3): exits 0 when this CPU has
// what -march=x86-64-v3 lets the compiler use (AVX2, BMI1/2, F16C, LZCNT, MOVBE; FMA too, which
// the build leaves out). A compiler that cannot name the level fails to build this: v2 is tried.
int main() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("x86-64-v3") ? 0 : 1;
}
