/*
 * Provokes every DEFLECT_ERR_* status code that deflect's C API can return, once, from C,
 * and checks the code. Prints one line per code; exits non-zero on the first mismatch.
 *
 *   status_codes MAP.csv
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "deflect.h"

static int failures = 0;

static void expect(const char *what, DeflectStatus got, DeflectStatus want) {
    printf("%-28s %4d  %s%s\n", what, (int)got, deflect_status_message(got),
           got == want ? "" : "  <-- WRONG");
    if (got != want) {
        ++failures;
    }
}

/* A valid JSON map with one force and one displacement axis: the planar corrector refuses it
 * at creation. */
static const char *ONE_AXIS_JSON =
    "{\"format_version\": 1,"
    " \"units\": {\"position\": \"m\", \"force\": \"N (moments N m)\","
    " \"displacement\": \"m (rotations rad)\", \"slope\": \"displacement unit / force unit\"},"
    " \"layout\": \"\", \"n_force\": 1, \"n_displacement\": 1,"
    " \"x\": [0.1, 0.3], \"y\": [-0.1, 0.1],"
    " \"slopes\": [1e-6, 1e-6, 1e-6, 1e-6], \"offsets\": [0, 0, 0, 0],"
    " \"options\": {\"interpolation\": \"bilinear\", \"out_of_grid\": \"clamp\"}}";

int main(int argc, char **argv) {
    const char *map_path = argc > 1 ? argv[1] : "data/paksoy2025_compliance_oc.csv";
    char err[256];
    DeflectComplianceMap *map = NULL;
    if (deflect_compliance_map_load_paper_csv(map_path, DEFLECT_FORCE_UNIT_NEWTON,
                                              DEFLECT_LENGTH_UNIT_MILLIMETRE, &map, err,
                                              sizeof err) != DEFLECT_OK) {
        fprintf(stderr, "cannot load %s: %s\n", map_path, err);
        return 1;
    }
    DeflectLimits limits;
    DeflectTrajectory2 *trajectory = NULL;
    DeflectDalembert *corrector = NULL;
    if (deflect_paper_limits(5, &limits) != DEFLECT_OK ||
        deflect_trajectory2_line((const double[2]){0.222132, -0.075},
                                 (const double[2]){0.222132, 0.075}, &limits,
                                 &trajectory) != DEFLECT_OK ||
        deflect_dalembert_create(NULL, map, DEFLECT_PAPER_MASS, 0, 0.0, &corrector) !=
            DEFLECT_OK) {
        fprintf(stderr, "setup failed\n");
        return 1;
    }
    const double zero[2] = {0.0, 0.0};
    const double inside[2] = {0.222132, 0.0};
    double out[2];
    DeflectState2 state;
    DeflectCorrectedTick2 tick;

    expect("ok", deflect_dalembert_step(corrector, inside, zero, &tick), DEFLECT_OK);
    expect("DEFLECT_ERR_NULL", deflect_paper_limits(5, NULL), DEFLECT_ERR_NULL);
    expect("DEFLECT_ERR_NON_FINITE", deflect_trajectory2_sample(trajectory, NAN, &state),
           DEFLECT_ERR_NON_FINITE);
    const double force3[3] = {1.0, 2.0, 3.0};
    expect("DEFLECT_ERR_WRONG_LENGTH",
           deflect_compliance_map_displacement(map, inside, force3, 3, out, 2, NULL),
           DEFLECT_ERR_WRONG_LENGTH);
    DeflectComplianceMap *missing = NULL;
    err[0] = '\0';
    expect("DEFLECT_ERR_LOAD",
           deflect_compliance_map_load_paper_csv("/nonexistent/map.csv", DEFLECT_FORCE_UNIT_NEWTON,
                                                 DEFLECT_LENGTH_UNIT_MILLIMETRE, &missing, err,
                                                 sizeof err),
           DEFLECT_ERR_LOAD);
    if (missing != NULL || strstr(err, "/nonexistent/map.csv") == NULL) {
        printf("  load error message missing or handle not NULL: '%s'\n", err);
        ++failures;
    } else {
        printf("  message: %s\n", err);
    }
    /* The map's default policy refuses positions outside its grid. */
    expect("DEFLECT_ERR_OUT_OF_GRID",
           deflect_compliance_map_displacement(map, zero, zero, 2, out, 2, NULL),
           DEFLECT_ERR_OUT_OF_GRID);
    /* From here on clamp, so that the robot's own limits are reached. The corrector holds the
     * copy of the map made at its creation: make one from the clamping map. */
    deflect_compliance_map_set_options(map, DEFLECT_INTERPOLATION_BILINEAR,
                                       DEFLECT_OUT_OF_GRID_CLAMP);
    DeflectDalembert *clamped = NULL;
    if (deflect_dalembert_create(NULL, map, DEFLECT_PAPER_MASS, 0, 0.0, &clamped) != DEFLECT_OK) {
        fprintf(stderr, "clamped corrector setup failed\n");
        return 1;
    }
    const double far[2] = {1.0, 0.0};
    expect("DEFLECT_ERR_OUT_OF_WORKSPACE", deflect_dalembert_step(clamped, far, zero, &tick),
           DEFLECT_ERR_OUT_OF_WORKSPACE);
    const double centre[2] = {0.001, 0.0};
    expect("DEFLECT_ERR_SINGULAR", deflect_dalembert_step(clamped, centre, zero, &tick),
           DEFLECT_ERR_SINGULAR);
    expect("DEFLECT_ERR_INVALID_ARGUMENT", deflect_paper_limits(9, &limits),
           DEFLECT_ERR_INVALID_ARGUMENT);
    DeflectComplianceMap *one_axis = NULL;
    DeflectStatus s = deflect_compliance_map_from_json(ONE_AXIS_JSON, &one_axis, err, sizeof err);
    if (s != DEFLECT_OK) {
        printf("one-axis JSON map did not load: %s\n", err);
        ++failures;
    } else {
        DeflectDalembert *refused = clamped; /* not NULL: a failed create must set it to NULL */
        expect("DEFLECT_ERR_MAP_DIMENSION",
               deflect_dalembert_create(NULL, one_axis, DEFLECT_PAPER_MASS, 0, 0.0, &refused),
               DEFLECT_ERR_MAP_DIMENSION);
        if (refused != NULL) {
            printf("  a refused create left its handle output non-NULL\n");
            ++failures;
        }
    }
    expect("DEFLECT_ERR_PANIC", deflect_test_panic(), DEFLECT_ERR_PANIC);
    /* NULL handles are no-ops for destroy. */
    deflect_compliance_map_destroy(NULL);

    deflect_compliance_map_destroy(one_axis);
    deflect_dalembert_destroy(clamped);
    deflect_dalembert_destroy(corrector);
    deflect_trajectory2_destroy(trajectory);
    deflect_compliance_map_destroy(map);
    printf("%d passed, %d failed\n", 11 - failures, failures);
    return failures == 0 ? 0 : 1;
}
