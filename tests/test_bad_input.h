/* home-hardening-tests: the tests of the other test_bad_input_*.c files, run after the table. */
#ifndef HOME_TEST_BAD_INPUT_H
#define HOME_TEST_BAD_INPUT_H
#include "home.h"

/* Same keypoints, field by field (struct padding is never compared). */
int same_features(const home_features *a, const home_features *b);
#define HARD_TESTS_MORE(X) \
    X(fails_constant_and_noise) X(fails_single_edge) X(fails_unrelated_scenes) \
    X(output_independent_of_arena_and_layout) X(stack_painted)
#endif
