/*
 * The paper's 2 kHz D'Alembert correction loop through deflect's C API (Paksoy et al.,
 * section 3.3): the 150 mm y-line of the planar parallel robot at 5 g, corrected with the
 * shipped OC compliance map (forces in N, displacements in mm), one-shot update, m* = 5 kg.
 *
 *   dalembert_y_line MAP.csv                 prints one line per tick (%.17g):
 *                                            k t desired_x desired_y commanded_x commanded_y
 *                                            theta_a theta_b
 *   dalembert_y_line MAP.csv --latency N     times N ticks (sample + step, wrapping around the
 *                                            motion) and prints median, p99.9 and max in ns
 *
 * Build: see examples/c/build_and_run.sh.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "deflect.h"

#define CHECK(call)                                                                    \
    do {                                                                               \
        DeflectStatus status_ = (call);                                                \
        if (status_ != DEFLECT_OK) {                                                   \
            fprintf(stderr, "%s failed: %d (%s)\n", #call, (int)status_,               \
                    deflect_status_message(status_));                                  \
            return 1;                                                                  \
        }                                                                              \
    } while (0)

static int compare_u64(const void *a, const void *b) {
    unsigned long long x = *(const unsigned long long *)a, y = *(const unsigned long long *)b;
    return (x > y) - (x < y);
}

static unsigned long long now_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (unsigned long long)ts.tv_sec * 1000000000ull + (unsigned long long)ts.tv_nsec;
}

int main(int argc, char **argv) {
    const char *map_path = argc > 1 ? argv[1] : "data/paksoy2025_compliance_oc.csv";
    long latency_ticks = 0;
    if (argc > 3 && strcmp(argv[2], "--latency") == 0) {
        latency_ticks = strtol(argv[3], NULL, 10);
    }

    /* Init time: load and plan (allocates). */
    char err[512];
    DeflectComplianceMap *map = NULL;
    if (deflect_compliance_map_load_paper_csv(map_path, DEFLECT_FORCE_UNIT_NEWTON,
                                              DEFLECT_LENGTH_UNIT_MILLIMETRE, &map, err,
                                              sizeof err) != DEFLECT_OK) {
        fprintf(stderr, "cannot load the compliance map: %s\n", err);
        return 1;
    }
    CHECK(deflect_compliance_map_set_options(map, DEFLECT_INTERPOLATION_BILINEAR,
                                             DEFLECT_OUT_OF_GRID_CLAMP));
    DeflectLimits limits;
    CHECK(deflect_paper_limits(5, &limits));
    const double start[2] = {0.222132, -0.075};
    const double end[2] = {0.222132, 0.075};
    DeflectTrajectory2 *trajectory = NULL;
    CHECK(deflect_trajectory2_line(start, end, &limits, &trajectory));
    /* The corrector copies the map, with its options (clamp at the grid boundary). */
    DeflectDalembert *corrector = NULL;
    CHECK(deflect_dalembert_create(NULL, map, DEFLECT_PAPER_MASS, 0, 0.0, &corrector));
    size_t ticks = 0;
    CHECK(deflect_trajectory2_tick_count(trajectory, DEFLECT_PAPER_RATE_HZ, &ticks));
    double duration = 0.0;
    CHECK(deflect_trajectory2_duration(trajectory, &duration));

    /* The servo loop: no allocation from here on. The corrector keeps the last joints. */
    DeflectState2 state;
    DeflectCorrectedTick2 tick;
    if (latency_ticks <= 0) {
        printf("# k t desired_x desired_y commanded_x commanded_y theta_a theta_b "
               "(s, m, rad)\n");
        for (size_t k = 0; k < ticks; ++k) {
            double t = 0.0;
            CHECK(deflect_trajectory2_tick_time(trajectory, DEFLECT_PAPER_RATE_HZ, k, &t));
            CHECK(deflect_trajectory2_sample(trajectory, t, &state));
            CHECK(deflect_dalembert_step(corrector, state.position, state.acceleration, &tick));
            printf("%zu %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", k, t, tick.desired[0],
                   tick.desired[1], tick.commanded[0], tick.commanded[1], tick.joints[0],
                   tick.joints[1]);
        }
    } else {
        unsigned long long *ns = malloc((size_t)latency_ticks * sizeof *ns);
        if (ns == NULL) {
            return 1;
        }
        for (long i = -10000; i < latency_ticks; ++i) { /* 10000 warm-up ticks */
            double t = (double)(i < 0 ? i + 10000 : i) / DEFLECT_PAPER_RATE_HZ;
            t -= duration * (double)(long)(t / duration);
            unsigned long long t0 = now_ns();
            DeflectStatus s1 = deflect_trajectory2_sample(trajectory, t, &state);
            DeflectStatus s2 =
                deflect_dalembert_step(corrector, state.position, state.acceleration, &tick);
            unsigned long long t1 = now_ns();
            if (s1 != DEFLECT_OK || s2 != DEFLECT_OK) {
                fprintf(stderr, "tick %ld failed: %d %d\n", i, (int)s1, (int)s2);
                return 1;
            }
            if (i >= 0) {
                ns[i] = t1 - t0;
            }
        }
        qsort(ns, (size_t)latency_ticks, sizeof *ns, compare_u64);
        size_t n = (size_t)latency_ticks;
        printf("C API dalembert tick (sample + step, one-shot): ticks %zu  median %llu ns  "
               "p99.9 %llu ns  max %llu ns\n",
               n, ns[(size_t)((double)(n - 1) * 0.5 + 0.5)],
               ns[(size_t)((double)(n - 1) * 0.999 + 0.5)], ns[n - 1]);
        free(ns);
    }

    deflect_dalembert_destroy(corrector);
    deflect_trajectory2_destroy(trajectory);
    deflect_compliance_map_destroy(map);
    return 0;
}
