/* Runs LLVMFuzzerTestOneInput on every file named on the command line (the seed corpus
 * and the regression inputs), for builds without libFuzzer: every crash the fuzzer ever
 * found stays a test in the ordinary and the sanitizer builds. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv) {
  int ran = 0;
  for (int i = 1; i < argc; ++i) {
    FILE *f = fopen(argv[i], "rb");
    if (!f) {
      fprintf(stderr, "replay: cannot open %s\n", argv[i]);
      return 2;
    }
    static uint8_t buf[1 << 16];
    const size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    LLVMFuzzerTestOneInput(buf, n);
    ++ran;
  }
  printf("replay: %d inputs ran\n", ran);
  return ran > 0 ? 0 : 1;
}
