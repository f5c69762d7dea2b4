// The paper's 2 kHz D'Alembert correction loop through deflect's C API, from C++: the same
// motion and output as examples/c/dalembert_y_line.c (150 mm y-line at 5 g, shipped OC map,
// one-shot update, m* = 5 kg), with the handles owned by std::unique_ptr.
//
//   dalembert_y_line_cpp MAP.csv      prints one line per tick (%.17g):
//                                     k t desired_x desired_y commanded_x commanded_y
//                                     theta_a theta_b
//
// Build: see examples/cpp/build_and_run.sh.
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "deflect.h"

namespace {

// Throws on any status other than DEFLECT_OK (init time only; the loop below checks codes).
void check(DeflectStatus status, const char *what) {
    if (status != DEFLECT_OK) {
        throw std::runtime_error(std::string(what) + ": " + deflect_status_message(status));
    }
}

struct MapDeleter {
    void operator()(DeflectComplianceMap *p) const noexcept { deflect_compliance_map_destroy(p); }
};
struct TrajectoryDeleter {
    void operator()(DeflectTrajectory2 *p) const noexcept { deflect_trajectory2_destroy(p); }
};
struct CorrectorDeleter {
    void operator()(DeflectDalembert *p) const noexcept { deflect_dalembert_destroy(p); }
};
using Map = std::unique_ptr<DeflectComplianceMap, MapDeleter>;
using Trajectory = std::unique_ptr<DeflectTrajectory2, TrajectoryDeleter>;
using Corrector = std::unique_ptr<DeflectDalembert, CorrectorDeleter>;

Map load_map(const char *path) {
    char err[512] = {0};
    DeflectComplianceMap *raw = nullptr;
    if (deflect_compliance_map_load_paper_csv(path, DEFLECT_FORCE_UNIT_NEWTON,
                                              DEFLECT_LENGTH_UNIT_MILLIMETRE, &raw, err,
                                              sizeof err) != DEFLECT_OK) {
        throw std::runtime_error(std::string("cannot load the compliance map: ") + err);
    }
    return Map(raw);
}

}  // namespace

int main(int argc, char **argv) try {
    const char *map_path = argc > 1 ? argv[1] : "data/paksoy2025_compliance_oc.csv";
    Map map = load_map(map_path);
    check(deflect_compliance_map_set_options(map.get(), DEFLECT_INTERPOLATION_BILINEAR,
                                             DEFLECT_OUT_OF_GRID_CLAMP),
          "set_options");
    DeflectLimits limits{};
    check(deflect_paper_limits(5, &limits), "paper_limits");
    const double start[2] = {0.222132, -0.075};
    const double end[2] = {0.222132, 0.075};
    DeflectTrajectory2 *raw_trajectory = nullptr;
    check(deflect_trajectory2_line(start, end, &limits, &raw_trajectory), "trajectory2_line");
    Trajectory trajectory(raw_trajectory);
    DeflectDalembert *raw_corrector = nullptr;
    // The corrector copies the map, with its options (clamp at the grid boundary).
    check(deflect_dalembert_create(nullptr, map.get(), DEFLECT_PAPER_MASS, 0, 0.0,
                                   &raw_corrector),
          "dalembert_create");
    Corrector corrector(raw_corrector);
    std::size_t ticks = 0;
    check(deflect_trajectory2_tick_count(trajectory.get(), DEFLECT_PAPER_RATE_HZ, &ticks),
          "tick_count");

    // The servo loop: no allocation from here on. The corrector keeps the last joints.
    std::printf("# k t desired_x desired_y commanded_x commanded_y theta_a theta_b (s, m, rad)\n");
    for (std::size_t k = 0; k < ticks; ++k) {
        double t = 0.0;
        DeflectState2 state{};
        DeflectCorrectedTick2 tick{};
        if (deflect_trajectory2_tick_time(trajectory.get(), DEFLECT_PAPER_RATE_HZ, k, &t) !=
                DEFLECT_OK ||
            deflect_trajectory2_sample(trajectory.get(), t, &state) != DEFLECT_OK) {
            std::fprintf(stderr, "tick %zu: sampling failed\n", k);
            return 1;
        }
        DeflectStatus s =
            deflect_dalembert_step(corrector.get(), state.position, state.acceleration, &tick);
        if (s != DEFLECT_OK) {
            // A real controller would hold the last command and stop the motion here.
            std::fprintf(stderr, "tick %zu: %s\n", k, deflect_status_message(s));
            return 1;
        }
        std::printf("%zu %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", k, t, tick.desired[0],
                    tick.desired[1], tick.commanded[0], tick.commanded[1], tick.joints[0],
                    tick.joints[1]);
    }
    return 0;
} catch (const std::exception &e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
}
