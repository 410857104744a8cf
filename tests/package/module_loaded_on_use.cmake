# Fails unless a library polydg loads on use (-DNEEDS=libopenvdb or libassimp) is needed only by
# its module (-DMODULE=libpolydg_openvdb.so or libpolydg_assimp.so): neither the installed
# `polydg` program nor the installed libpolydg.so may need it when they start (OpenVDB's symbols
# took two thirds of every command's start, assimp's 7.5 ms), and the module must be installed
# beside the library, needing it. With -DREAD=FILE, the installed program must also read FILE
# (through the installed module).
find_program(READELF readelf REQUIRED)
function(needed file out)
  execute_process(COMMAND ${READELF} -d ${file} OUTPUT_VARIABLE dynamic RESULT_VARIABLE failed)
  if(failed)
    message(FATAL_ERROR "readelf -d ${file} failed")
  endif()
  string(REGEX MATCHALL "Shared library: \\[[^]]*\\]" libraries "${dynamic}")
  set(${out} "${libraries}" PARENT_SCOPE)
endfunction()
file(GLOB library "${PREFIX}/lib*/libpolydg.so")
file(GLOB module "${PREFIX}/lib*/${MODULE}")
if(NOT library OR NOT module)
  message(FATAL_ERROR "libpolydg.so and ${MODULE} are not both installed under ${PREFIX}")
endif()
foreach(file "${PREFIX}/bin/polydg" ${library})
  needed(${file} libraries)
  if(libraries MATCHES "${NEEDS}")
    message(FATAL_ERROR "${file} needs ${NEEDS} at start: ${libraries}")
  endif()
endforeach()
needed(${module} libraries)
if(NOT libraries MATCHES "${NEEDS}")
  message(FATAL_ERROR "${module} does not need ${NEEDS}: ${libraries}")
endif()
if(READ)
  execute_process(COMMAND ${PREFIX}/bin/polydg info ${READ} --quiet
                  RESULT_VARIABLE failed ERROR_VARIABLE error)
  if(failed)
    message(FATAL_ERROR "the installed polydg cannot read ${READ}: ${error}")
  endif()
endif()
message(STATUS "polydg and libpolydg.so start without ${NEEDS}; ${MODULE} needs it")
