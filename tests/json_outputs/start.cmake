# Marks the start of a test run (the fixture setup of the JSON audit): the
# audit judges the files written after this mark only.  Nothing is removed,
# so a second ctest running beside this one loses nothing.
file(MAKE_DIRECTORY ${DIR})
file(TOUCH ${DIR}/.run_started)
