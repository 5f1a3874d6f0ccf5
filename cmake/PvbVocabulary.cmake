# The default place-recognition vocabulary (docs/place_recognition.md,
# "The default vocabulary").  It is trained at build time by `pvbench vocab`
# (about 25 s on 2 cores: 452 images, 442 537 descriptors, 19.3 MB), from
# scenarios whose layouts place recognition is never measured on, at seeds
# it is never measured at, plus the real Oxford images of ../shared when
# they are there.  The same inputs and seed give the same bytes.
# PVB_PREBUILT_VOCABULARY names a file to use instead (the sanitizer build
# takes the main build's).  Included before the layers: sets
# PVB_DEFAULT_VOCABULARY_FILE, which slam/core compiles in; pvb_add_vocabulary()
# adds the training once pvbench exists.
set(PVB_PREBUILT_VOCABULARY "" CACHE FILEPATH
    "an existing vocabulary file to use as the default instead of training one at build time")
if(PVB_PREBUILT_VOCABULARY)
  set(PVB_DEFAULT_VOCABULARY_FILE "${PVB_PREBUILT_VOCABULARY}")
else()
  set(PVB_DEFAULT_VOCABULARY_FILE "${CMAKE_BINARY_DIR}/vocabulary/pvbench_orb.pvbvoc")
endif()

function(pvb_add_vocabulary)
  if(PVB_PREBUILT_VOCABULARY)
    return()
  endif()
  set(args)
  set(deps)
  foreach(name pv_station dusty_panels low_sun_glare fast_turns high_noise tracking_failure)
    list(APPEND args --scenario ${PROJECT_SOURCE_DIR}/scenes/${name}.yaml)
    list(APPEND deps ${PROJECT_SOURCE_DIR}/scenes/${name}.yaml)
  endforeach()
  set(images)
  foreach(dir wall trees)
    if(IS_DIRECTORY ${PROJECT_SOURCE_DIR}/../shared/data/oxford/${dir})
      list(APPEND images --images ${PROJECT_SOURCE_DIR}/../shared/data/oxford/${dir})
    endif()
  endforeach()
  set(args ${images} ${args})  # the order of the images is part of the training
  set(gl auto)
  if(TARGET pvb_gl_osmesa)
    set(gl osmesa)  # the backend the shipped figures were measured with
  endif()
  get_filename_component(dir ${PVB_DEFAULT_VOCABULARY_FILE} DIRECTORY)
  # $<TARGET_FILE:pvbench>: built first, but a rebuilt pvbench does not
  # retrain (only a changed scenario file does).
  add_custom_command(OUTPUT ${PVB_DEFAULT_VOCABULARY_FILE}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
    COMMAND $<TARGET_FILE:pvbench> vocab --out ${PVB_DEFAULT_VOCABULARY_FILE} ${args}
            --seeds 101-102 --every 20 --gl ${gl}
    DEPENDS ${deps}
    COMMENT "Training the default place-recognition vocabulary (pvbench vocab)"
    VERBATIM)
  add_custom_target(pvb_vocabulary ALL DEPENDS ${PVB_DEFAULT_VOCABULARY_FILE})
  add_dependencies(pvb_vocabulary pvbench)
endfunction()
