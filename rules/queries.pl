% Queries (paper IV): the three questions asked of the theory, as atoms whose outcomes are
% mutually exclusive, and the evidence they are conditioned on. The engine
% (tg_drake/logic/engine.py) computes P(outcome, evidence) for every outcome and divides by the
% sum over the outcomes: that explicit normalisation is the paper's mutual-exclusiveness
% assumption. Exclusive mode: an object has exactly one category and one part is grasped.
% Non-exclusive mode: the category_is/part_is marginals, normalised.

% Category.
category_is(C) :- cat(o, C).
other_category(C) :- cat(o, C2), C2 \= C.
only_category(C) :- cat(o, C), \+ other_category(C).
single_category :- only_category(_).
consistent :- \+ incompatible(o).
consistent_single :- single_category, consistent.

% Task (task/1 is exclusive already: it is the given task or drawn from the task prior).
task_is(T) :- task(T), affords(o, T).

% Pre-grasp part for the task.
grasp_for_task(R) :- task(T), grasp(o, T, R).
other_grasp(R) :- task(T), grasp(o, T, R2), R2 \= R.
only_grasp(R) :- grasp_for_task(R), \+ other_grasp(R).
ruled_out :- task(T), violation(o, T).
part_is(R) :- grasp_for_task(R), \+ ruled_out.
only_part_is(R) :- only_grasp(R), \+ ruled_out.
