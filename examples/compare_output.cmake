# Runs PROGRAM --options-markdown and fails unless its output equals the file DOC; the text it
# generated is then left in GENERATED (in the build tree: a test writes nothing into the sources).
execute_process(COMMAND "${PROGRAM}" --options-markdown RESULT_VARIABLE rc OUTPUT_VARIABLE generated ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} --options-markdown: exit code ${rc}\n${err}")
endif()
file(READ "${DOC}" written)
if(NOT generated STREQUAL written)
  file(WRITE "${GENERATED}" "${generated}")
  message(FATAL_ERROR "${DOC} differs from the descriptions (the generated text is in ${GENERATED}; "
                      "regenerate with: ${PROGRAM} --options-markdown > ${DOC})")
endif()
