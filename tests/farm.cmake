# Farm bakes on a real Slurm (tests/farm/README.md), label `farm`: each test starts its own
# one-node Slurm on localhost (scripts/slurm-local, munged, slurmctld, slurmd) and stops it by
# process id. RUN_SERIAL: the cluster takes both cores. Without Slurm installed a test fails,
# unless TREEANIM_FARM_SKIP_OK=1 lets it skip (exit 77). Included by CMakeLists.txt.
find_program(TREEANIM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
add_test(NAME farm.slurm_smoke COMMAND ${TREEANIM_PYTHON} ${CMAKE_SOURCE_DIR}/tests/farm/slurm_smoke.py)
set_tests_properties(farm.slurm_smoke PROPERTIES LABELS farm RUN_SERIAL TRUE SKIP_RETURN_CODE 77 TIMEOUT 300)
add_test(NAME farm.forest_requeue
  COMMAND ${TREEANIM_PYTHON} ${CMAKE_SOURCE_DIR}/tests/farm/forest_requeue.py $<TARGET_FILE:treeanim>)
set_tests_properties(farm.forest_requeue PROPERTIES LABELS farm RUN_SERIAL TRUE SKIP_RETURN_CODE 77 TIMEOUT 480)
