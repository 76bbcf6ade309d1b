/* home-hardening-tests: the tests of the other test_bad_input_*.c files, run after the table. */
#ifndef HOME_TEST_BAD_INPUT_H
#define HOME_TEST_BAD_INPUT_H
#define HARD_TESTS_MORE(X)
#endif
