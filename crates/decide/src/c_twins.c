/* specula's C twins: each lobe's formula (docs/spec.md section 2) as the plain C loop a C
 * programmer would write, compiled by `specula bench lobes` with
 * `-O3 -ffast-math -mavx2 -mfma` (gcc vectorises the loops, and the exp/log calls through
 * glibc's libmvec). Written independently of specula's kernels: the peer they are measured
 * against, and a second opinion on their values.
 *
 * Usage: c_twins N SECONDS ROUNDS < COSINES (2048, one a line). For every twin, prints one
 * line: its id, its rate (evaluations per second on one thread over those cosines, best of
 * 3 runs of at least SECONDS each, reading the clock every ROUNDS rounds, as specula's
 * harness does), then its 2048 values. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define SIZE 2048

typedef void (*loop_fn)(const float *restrict t, float *restrict out, int size, float n);

static void pow_loop(const float *restrict t, float *restrict out, int size, float n) {
    for (int i = 0; i < size; i++) out[i] = exp2f(n * log2f(t[i]));
}

static void schlick_loop(const float *restrict t, float *restrict out, int size, float n) {
    for (int i = 0; i < size; i++) out[i] = t[i] / (n - n * t[i] + t[i]);
}

static void logexp_loop(const float *restrict t, float *restrict out, int size, float n) {
    for (int i = 0; i < size; i++) {
        float y = n * log2f(t[i]);
        out[i] = fmaxf(0.0f, 1.0f - 0.5f * log2f(1.0f - y));
    }
}

static void cosquad_loop(const float *restrict t, float *restrict out, int size, float n) {
    float a = (n + 1.0f) / 17.0f;
    for (int i = 0; i < size; i++) {
        float x = fmaxf(0.0f, a * (t[i] - 1.0f) + 1.0f);
        x *= x;
        x *= x;
        x *= x;
        x *= x;
        out[i] = x;
    }
}

static void sg_loop(const float *restrict t, float *restrict out, int size, float n) {
    for (int i = 0; i < size; i++) out[i] = expf(n * (t[i] - 1.0f));
}

static const struct {
    const char *id;
    loop_fn loop;
} twins[] = {
    {"pow", pow_loop},
    {"schlick", schlick_loop},
    {"logexp", logexp_loop},
    {"cosquad", cosquad_loop},
    {"sg", sg_loop},
};

static double now(void) {
    struct timespec clock;
    clock_gettime(CLOCK_MONOTONIC, &clock);
    return clock.tv_sec + 1e-9 * clock.tv_nsec;
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: c_twins N SECONDS ROUNDS\n");
        return 2;
    }
    float n = strtof(argv[1], NULL);
    double seconds = strtod(argv[2], NULL);
    long rounds_per_clock = strtol(argv[3], NULL, 10);
    static float t[SIZE], out[SIZE];
    /* The cosines of specula's `bench lobes` (decide::rates::cosines), one per line on
     * standard input: read, not recomputed, since -ffast-math may contract the formula. */
    for (int i = 0; i < SIZE; i++) {
        if (scanf("%f", &t[i]) != 1) {
            fprintf(stderr, "c_twins: expected %d cosines on standard input\n", SIZE);
            return 2;
        }
    }
    for (size_t k = 0; k < sizeof twins / sizeof twins[0]; k++) {
        double best = 0.0;
        for (int run = 0; run < 3; run++) {
            double started = now(), elapsed;
            long rounds = 0;
            do {
                for (long round = 0; round < rounds_per_clock; round++) {
                    twins[k].loop(t, out, SIZE, n);
                    /* The results escape, so the loop cannot be elided. */
                    __asm__ volatile("" : : "r"(out) : "memory");
                }
                rounds += rounds_per_clock;
            } while ((elapsed = now() - started) < seconds);
            double rate = rounds * (double)SIZE / elapsed;
            if (rate > best) best = rate;
        }
        printf("%s %.6e", twins[k].id, best);
        for (int i = 0; i < SIZE; i++) printf(" %.9g", out[i]);
        printf("\n");
    }
    return 0;
}
