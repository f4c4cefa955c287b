% Task ontology (paper IV-B): the 7 tasks and their super-tasks pour and pp_in (p&pIn).
% The paper's names map to atoms in tg_drake/logic/names.py: pass, pourOut -> pour_out,
% pourIn -> pour_in, p&pInUpright -> pp_in_upright, p&pInUpsidedown -> pp_in_upsidedown,
% p&pInSideways -> pp_in_sideways, p&pOn -> pp_on. The super-task place (p&pIn and p&pOn) is ours:
% the general grasp model uses it (rules/README.md, table 2).

leaf_task(pass). leaf_task(pour_out). leaf_task(pour_in). leaf_task(pp_in_upright).
leaf_task(pp_in_upsidedown). leaf_task(pp_in_sideways). leaf_task(pp_on).

subtask(pour_out, pour).
subtask(pour_in, pour).
subtask(pp_in_upright, pp_in).
subtask(pp_in_upsidedown, pp_in).
subtask(pp_in_sideways, pp_in).
subtask(pp_in, place).
subtask(pp_on, place).

% isa_task(T, S): task T is S or a sub-task of S (the paper's pour(T) :- pourIn(T). ...).
isa_task(T, T) :- leaf_task(T).
isa_task(T, S) :- subtask(T, S).
isa_task(T, S) :- subtask(T, M), isa_task(M, S).
