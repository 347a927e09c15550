/* One line per test function: PLUME_TEST(test_<module>_<what>). Append new tests here. */
PLUME_TEST(test_status_strerror)
