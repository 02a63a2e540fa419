# Real-client checks of the outputs (docs/outputs.md, "Checks"): one end-to-end bake of
# tests/golden/small_tree.json with the CLI, then each format opened by the tool its users use.
# Included by CMakeLists.txt inside TREEANIM_TESTS; labels "io;clients". The tools come from
# scripts/setup: python3-h5py, hdf5-tools, blender (apt) and tests/clients/node (npm ci).
set(io_bake_dir ${CMAKE_BINARY_DIR}/io_clients)
set(io_scene ${CMAKE_SOURCE_DIR}/tests/golden/small_tree.json)
set(io_clients ${CMAKE_SOURCE_DIR}/tests/clients)

# A client test whose tool is missing fails with the reason instead of silently passing.
function(io_client_test name program)
  if(program)
    add_test(NAME ${name} COMMAND ${program} ${ARGN} WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  else()
    add_test(NAME ${name} COMMAND sh -c "echo '${name}: tool not installed (run scripts/setup)'; exit 1")
  endif()
  set_tests_properties(${name} PROPERTIES LABELS "io;clients" FIXTURES_REQUIRED io_bake TIMEOUT 300)
endfunction()

# The scene's own outputs, then the same scene again with the optional outputs (normals, a
# quantized HDF5, MDD) into options/, beside a plain HDF5 bake with normals to compare with.
set(io_options_dir ${io_bake_dir}/options)
set(io_options_outputs "[{\"format\":\"hdf5\",\"path\":\"plain.h5\",\"normals\":true},\
{\"format\":\"hdf5\",\"path\":\"quantized.h5\",\"quantize\":0.0001},\
{\"format\":\"obj\",\"path\":\"obj/tree\",\"normals\":true,\"frame_step\":5},\
{\"format\":\"gltf\",\"path\":\"gltf/tree\",\"normals\":true,\"frame_step\":6},\
{\"format\":\"glb\",\"path\":\"normals.glb\",\"normals\":true},{\"format\":\"mdd\",\"path\":\"tree.mdd\"},\
{\"format\":\"vat\",\"path\":\"vat/tree\"},{\"format\":\"vat\",\"path\":\"vat_half/tree\",\"precision\":\"half\",\"texture_width\":100},\
{\"format\":\"skinned_glb\",\"path\":\"skinned.glb\"},{\"format\":\"skinned_glb\",\"path\":\"skinned4.glb\",\"max_joints\":4}]")
# And a seamless loop of the same tree (tests/clients/scenes/loop.json); and the scene on samples
# (hsm.particles "samples"), whose skinned GLB carries the solver's own cluster motions.
set(io_loop_dir ${io_bake_dir}/loop)
set(io_samples_dir ${io_bake_dir}/samples)
set(io_samples_outputs "[{\"format\":\"hdf5\",\"path\":\"plain.h5\"},{\"format\":\"skinned_glb\",\"path\":\"skinned.glb\"}]")
add_test(NAME io_clients_bake
         COMMAND sh -c "rm -rf '${io_bake_dir}' && '$<TARGET_FILE:treeanim>' run '${io_scene}' -o '${io_bake_dir}' --quiet && '$<TARGET_FILE:treeanim>' run '${io_scene}' -o '${io_options_dir}' --quiet --set 'outputs=${io_options_outputs}' && '$<TARGET_FILE:treeanim>' run '${io_clients}/scenes/loop.json' -o '${io_loop_dir}' --quiet && exec '$<TARGET_FILE:treeanim>' run '${io_scene}' -o '${io_samples_dir}' --quiet --set 'hsm.particles=\"samples\"' --set hsm.leaf_detach_force=0 --set 'outputs=${io_samples_outputs}'"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(io_clients_bake PROPERTIES LABELS "io;clients" FIXTURES_SETUP io_bake TIMEOUT 120)

find_program(TREEANIM_SYSTEM_PYTHON python3 PATHS /usr/bin NO_DEFAULT_PATH)
io_client_test(io_clients_h5py "${TREEANIM_SYSTEM_PYTHON}" ${io_clients}/check_hdf5.py
               ${io_bake_dir}/small_tree.h5 --obj ${io_bake_dir}/obj/small_tree --pc2 ${io_bake_dir}/small_tree.pc2
               --velocities yes --compression 4)

# Normals against normals recomputed from each frame's triangles (and equal in OBJ and GLB),
# the quantized bake within half a step of the plain one, the MDD equal to the bake.
io_client_test(io_clients_bake_options "${TREEANIM_SYSTEM_PYTHON}" ${io_clients}/check_bake_options.py
               ${io_options_dir}/plain.h5 --quantized ${io_options_dir}/quantized.h5 --mdd ${io_options_dir}/tree.mdd
               --obj ${io_options_dir}/obj/tree --glb ${io_options_dir}/normals.glb)

# The loop: one period at its own times, a seam within twice the median frame step, the GLB's
# closing key, the VAT's flag.
io_client_test(io_clients_loop "${TREEANIM_SYSTEM_PYTHON}" ${io_clients}/check_loop.py
               ${io_loop_dir}/loop.h5 ${io_loop_dir}/loop.glb ${io_loop_dir}/vat/loop.json)

# Golden bake: positions, velocities and every other number within 1e-5 (m, m/s, kg), strings
# and attributes exact. scripts/update-golden regenerates tests/golden/*.h5 on purpose.
find_program(TREEANIM_H5DIFF h5diff)
io_client_test(io_clients_golden "${TREEANIM_H5DIFF}" --delta=1e-5
               ${CMAKE_SOURCE_DIR}/tests/golden/small_tree.h5 ${io_bake_dir}/small_tree.h5)

find_program(TREEANIM_NODE node)
if(NOT EXISTS ${io_clients}/node/node_modules/gltf-validator)
  set(TREEANIM_NODE "")  # scripts/setup runs `npm ci` in tests/clients/node
endif()
io_client_test(io_clients_gltf_validator "${TREEANIM_NODE}" ${io_clients}/node/validate_gltf.js
               ${io_bake_dir}/small_tree.glb ${io_bake_dir}/gltf/small_tree.0000.glb
               ${io_bake_dir}/gltf/small_tree.0006.glb ${io_options_dir}/normals.glb
               ${io_options_dir}/gltf/tree.0006.glb ${io_options_dir}/vat/tree.glb ${io_options_dir}/skinned.glb
               ${io_options_dir}/skinned4.glb ${io_loop_dir}/loop.glb ${io_loop_dir}/skinned.glb
               ${io_samples_dir}/skinned.glb)

find_program(TREEANIM_BLENDER blender)
io_client_test(io_clients_blender "${TREEANIM_BLENDER}" -b --factory-startup --python
               ${io_clients}/check_blender.py -- ${io_bake_dir}/small_tree.h5 ${io_bake_dir}/small_tree.glb
               ${io_bake_dir}/small_tree.pc2 ${io_bake_dir}/small_tree.rest.obj
               ${io_options_dir}/tree.mdd ${io_options_dir}/tree.rest.obj)

# Vertex animation textures read by Blender (bpy.data.images.load): rest + texel gives the bake's
# frames to the texture's precision (float and half), the normals too, and the rest GLB's second
# UV map addresses each vertex's texel.
io_client_test(io_clients_blender_vat "${TREEANIM_BLENDER}" -b --factory-startup --python
               ${io_clients}/check_vat.py -- ${io_options_dir}/plain.h5 ${io_options_dir}/vat/tree
               ${io_options_dir}/vat_half/tree)

# The skinned GLB in Blender: the armature deforms the mesh to within 2e-5 m of the error the
# file claims (RMS per frame at four frames, and the largest), one joint per cluster and four.
io_client_test(io_clients_blender_skinned "${TREEANIM_BLENDER}" -b --factory-startup --python
               ${io_clients}/check_skinned.py -- ${io_options_dir}/plain.h5 ${io_options_dir}/skinned.glb
               ${io_options_dir}/skinned4.glb)
# A bake on samples: its skinned GLB's keys are the solver's cluster motions, the mesh's own
# placement, so the armature reproduces the bake to float rounding at every vertex that is not
# anchored (--exact), with leaves detaching off (a skin's weights cannot let a leaf go).
io_client_test(io_clients_blender_skinned_samples "${TREEANIM_BLENDER}" -b --factory-startup --python
               ${io_clients}/check_skinned.py -- --exact ${io_samples_dir}/plain.h5 ${io_samples_dir}/skinned.glb)

# A bad output path is refused before simulating, with exit code 4 and the path named.
add_test(NAME io_cli_unwritable_output
         COMMAND sh -c "message=$('$<TARGET_FILE:treeanim>' run '${io_scene}' -o /proc/treeanim-out --quiet 2>&1); code=$?; echo \"$message\"; test $code -eq 4 && echo \"$message\" | grep -q '/proc/treeanim-out/small_tree.h5: cannot create the folder'")
set_tests_properties(io_cli_unwritable_output PROPERTIES LABELS "io;clients")

# SIGINT in the middle of a bake: exit 130 and not one file left (folders made by the checks stay).
set(io_sigint_dir ${CMAKE_BINARY_DIR}/io_sigint)
add_test(NAME io_cli_sigint_leaves_nothing
         COMMAND sh -c "rm -rf '${io_sigint_dir}'; '$<TARGET_FILE:treeanim>' run '${io_scene}' -o '${io_sigint_dir}' --quiet --set time.frames=200000 --set 'outputs=[{\"format\":\"hdf5\",\"path\":\"bake.h5\"},{\"format\":\"obj\",\"path\":\"obj/tree\"},{\"format\":\"pc2\",\"path\":\"tree.pc2\"}]' & pid=$!; sleep 2; kill -INT $pid; wait $pid; code=$?; left=$(find '${io_sigint_dir}' -type f); echo \"exit $code, files left: $left\"; test $code -eq 130 && test -z \"$left\"")
set_tests_properties(io_cli_sigint_leaves_nothing PROPERTIES LABELS "io;clients" TIMEOUT 60)

# A write that fails (file-size limit with SIGXFSZ ignored, as ENOSPC behaves) while HDF5 holds
# the file: exit 4 naming the file and the cause, no temporary left, and no crash at exit
# (HDF5 1.10.8's exit handler used to segfault on the file whose close had failed).
set(io_efbig_dir ${CMAKE_BINARY_DIR}/io_efbig)
add_test(NAME io_cli_hdf5_file_too_large
         COMMAND sh -c "rm -rf '${io_efbig_dir}'; trap '' XFSZ; ulimit -f 200; message=$('$<TARGET_FILE:treeanim>' run '${io_scene}' -o '${io_efbig_dir}' --quiet --set time.frames=400 --set 'outputs=[{\"format\":\"hdf5\",\"path\":\"bake.h5\"}]' 2>&1); code=$?; left=$(find '${io_efbig_dir}' -type f); echo \"exit $code: $message; files left: $left\"; test $code -eq 4 && test -z \"$left\" && echo \"$message\" | grep -q 'bake.h5: HDF5 could not .* (File too large)'")
set_tests_properties(io_cli_hdf5_file_too_large PROPERTIES LABELS "io;clients" TIMEOUT 120)
