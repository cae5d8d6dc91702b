// Exit status 0 when the CPU running this has x86-64-v3 (AVX2, FMA, BMI1/2, ...): the probe of
// SGBAKE_X86_64_LEVEL=auto (CMakeLists.txt).
int main(void) {
  __builtin_cpu_init();
  return __builtin_cpu_supports("x86-64-v3") ? 0 : 1;
}
