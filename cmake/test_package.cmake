# ctest script: install nsp from the build tree into a scratch prefix, then build and run the
# consumer project against it with find_package, and again with add_subdirectory. Both builds
# compile and run the code snippets of the README (cmake/consumer/CMakeLists.txt): the installed
# build is given the README's path, the subdirectory build finds it in NSP_SOURCE_DIR. Last, the
# example host renderer examples/host against the installed package, and its --compare check.
# Inputs: NSP_SOURCE_DIR, NSP_BINARY_DIR, WORK_DIR, GENERATOR; optional NSP_README (default
# ${NSP_SOURCE_DIR}/README.md).
foreach(v NSP_SOURCE_DIR NSP_BINARY_DIR WORK_DIR)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "test_package.cmake needs -D${v}=...")
    endif()
endforeach()
if(NOT DEFINED NSP_README)
    set(NSP_README ${NSP_SOURCE_DIR}/README.md)
endif()
file(REMOVE_RECURSE ${WORK_DIR})

function(run)
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}")
    endif()
    message(STATUS "${out}")
endfunction()

run(${CMAKE_COMMAND} --install ${NSP_BINARY_DIR} --prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} -S ${NSP_SOURCE_DIR}/cmake/consumer -B ${WORK_DIR}/installed -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DNSP_README=${NSP_README})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/installed)
run(${WORK_DIR}/installed/consumer)

run(${CMAKE_COMMAND} -S ${NSP_SOURCE_DIR}/cmake/consumer -B ${WORK_DIR}/subdir -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DNSP_SOURCE_DIR=${NSP_SOURCE_DIR})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/subdir)
run(${WORK_DIR}/subdir/consumer)

# The example host renderer (examples/host), built against the installed package as a user would:
# its own geometry, lights and path loop on nsp's path-vertex kernels. --compare renders a scene
# both it and nsp::PathEstimator can render and fails unless their image means agree within 5
# standard errors.
run(${CMAKE_COMMAND} -S ${NSP_SOURCE_DIR}/examples/host -B ${WORK_DIR}/host -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/host)
run(${WORK_DIR}/host/nsp_host --compare)
