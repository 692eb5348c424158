# Tests of the Next-Best-Sense planner.
pl_add_gtest(test_nbs_choquet test/test_nbs_choquet.cpp LIBS picker_localisation_nbs)
pl_add_gtest(test_nbs_planner test/test_nbs_planner.cpp LIBS picker_localisation_nbs)
pl_add_gtest(test_nbs_tpf_planner test/test_nbs_tpf_planner.cpp LIBS picker_localisation_nbs)
