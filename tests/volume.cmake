# A wind volume through the binary (docs/scene.md `wind.volume`), label `volume`: every bad
# input exits 2, info and validate print the volume, a gust front crosses a three-tree forest
# and shards give the same bytes. The volumes are written at test time with python3-openvdb
# (tests/volume/write_volumes.py), which Debian installs for /usr/bin/python3 only.
foreach(volume_case bad info forest)
  add_test(NAME volume.${volume_case}
    COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/volume/volume_cli.py $<TARGET_FILE:treeanim> ${volume_case})
  set_tests_properties(volume.${volume_case} PROPERTIES LABELS volume TIMEOUT 600)
endforeach()
