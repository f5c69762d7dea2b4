/*
 * The 6-D D'Alembert correction of a serial arm through deflect's C API: the KR 300 of
 * robots/kr300 carries a 150 kg spindle (centre of mass 0.25 m along the tool axis) through a
 * pose motion of 0.33 m and 0.3 rad at about 1 g. Each 2 kHz tick samples the motion, and the
 * corrector turns the payload's inertial wrench through the arm's virtual-joint stiffness
 * into the joints at which the loaded arm reaches the desired pose. Any serial arm works:
 * pass its URDF, stiffness file and tip link.
 *
 *   serial_kr300_dalembert [URDF STIFFNESS TIP]   one line per tick (%.17g):
 *                                                 k t desired_xyz commanded_xyz q[0..6]
 *   serial_kr300_dalembert URDF STIFFNESS TIP --latency N
 *                                                 times N ticks (sample + step, forth and back
 *                                                 along the motion): median, p99.9, max in ns
 *
 * Build: see examples/c/build_and_run.sh (DEFLECT_EXAMPLE=serial_kr300_dalembert).
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
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

/* out = Rz(angle) * r for row-major 4 x 4 poses (rotation part only). */
static void turn_about_z(const double *in, double angle, double *out) {
    double c = cos(angle), s = sin(angle);
    memcpy(out, in, 16 * sizeof(double));
    for (int col = 0; col < 3; ++col) {
        double x = in[0 * 4 + col], y = in[1 * 4 + col];
        out[0 * 4 + col] = c * x - s * y;
        out[1 * 4 + col] = s * x + c * y;
    }
}

int main(int argc, char **argv) {
    const char *urdf = argc > 3 ? argv[1] : "robots/kr300/kr300_r2500.urdf";
    const char *stiffness = argc > 3 ? argv[2] : "robots/kr300/kr300_r2500_stiffness.toml";
    const char *tip = argc > 3 ? argv[3] : "tcp";
    long latency_ticks = 0;
    if (argc > 5 && strcmp(argv[4], "--latency") == 0) {
        latency_ticks = strtol(argv[5], NULL, 10);
    }

    /* Init time: load, plan, create (allocates). */
    char err[512];
    DeflectSerialRobot *robot = NULL;
    if (deflect_serial_robot_load(urdf, stiffness, tip, &robot, err, sizeof err) != DEFLECT_OK) {
        fprintf(stderr, "cannot load the robot: %s\n", err);
        return 1;
    }
    size_t dof = 0;
    CHECK(deflect_serial_robot_dof(robot, &dof, NULL));
    if (dof != 6) {
        fprintf(stderr, "this example's start pose is for a 6-joint arm, got %zu joints\n", dof);
        return 1;
    }
    const double q0[6] = {0.0, -0.9, 1.4, 0.0, 1.0708, 0.0};
    double start[16], end[16];
    CHECK(deflect_serial_robot_forward(robot, q0, dof, start));
    turn_about_z(start, 0.3, end);
    end[3] += 0.1;
    end[7] += 0.3;
    end[11] -= 0.1;
    const DeflectLimits linear = {2.0, 9.81, 200.0}, angular = {1.5, 8.0, 100.0};
    DeflectPoseMotion *motion = NULL;
    CHECK(deflect_pose_motion_line(start, end, &linear, &angular, &motion));
    const double rate = DEFLECT_PAPER_RATE_HZ;
    double duration = 0.0;
    size_t ticks = 0;
    CHECK(deflect_pose_motion_info(motion, rate, &duration, &ticks));

    const DeflectPayload spindle = {
        150.0, {0.0, 0.0, 0.25}, {4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 2.5}};
    DeflectSerialDalembert *corrector = NULL;
    CHECK(deflect_serial_dalembert_create(robot, &spindle, DEFLECT_SERIAL_EXACT, q0, dof,
                                          &corrector));

    DeflectPoseState state;
    DeflectSerialTick tick;
    if (latency_ticks <= 0) {
        double largest = 0.0;
        for (size_t k = 0; k < ticks; ++k) {
            double t = (k + 1 == ticks) ? duration : (double)k / rate;
            CHECK(deflect_pose_motion_sample(motion, t, &state));
            CHECK(deflect_serial_dalembert_step(corrector, &state, NULL, &tick));
            double dx = tick.commanded[3] - state.pose[3], dy = tick.commanded[7] - state.pose[7],
                   dz = tick.commanded[11] - state.pose[11];
            double c = sqrt(dx * dx + dy * dy + dz * dz);
            if (c > largest) largest = c;
            printf("%zu %.17g %.17g %.17g %.17g %.17g %.17g %.17g", k, t, state.pose[3],
                   state.pose[7], state.pose[11], tick.commanded[3], tick.commanded[7],
                   tick.commanded[11]);
            for (size_t j = 0; j < dof; ++j) printf(" %.17g", tick.joints[j]);
            printf("\n");
        }
        fprintf(stderr, "%zu ticks over %.4f s; largest TCP correction %.3f mm\n", ticks,
                duration, largest * 1e3);
    } else {
        unsigned long long *ns = malloc((size_t)latency_ticks * sizeof *ns);
        if (ns == NULL) return 1;
        int back = 0;
        for (long i = 0; i < latency_ticks; ++i) {
            size_t k = (size_t)i % ticks;
            if (k == 0) back = !back;
            size_t at = back ? k : ticks - 1 - k;
            double t = (at + 1 == ticks) ? duration : (double)at / rate;
            unsigned long long t0 = now_ns();
            CHECK(deflect_pose_motion_sample(motion, t, &state));
            CHECK(deflect_serial_dalembert_step(corrector, &state, NULL, &tick));
            ns[i] = now_ns() - t0;
        }
        qsort(ns, (size_t)latency_ticks, sizeof *ns, compare_u64);
        printf("serial tick (sample + step), %ld ticks: median %llu ns, p99.9 %llu ns, max %llu "
               "ns\n",
               latency_ticks, ns[latency_ticks / 2], ns[(long)(latency_ticks * 0.999)],
               ns[latency_ticks - 1]);
        free(ns);
    }
    deflect_serial_dalembert_destroy(corrector);
    deflect_pose_motion_destroy(motion);
    deflect_serial_robot_destroy(robot);
    return 0;
}
