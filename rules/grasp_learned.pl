% LEARNED grasp model: the probabilities of grasp_specific.pl fitted by ProbLog's learning from interpretations (EM, 2 iterations, log-likelihood -1512.80),
% starting from the hand-written values (worth 2 interpretations as a prior); data: 261 executed grasps of 81 scenes of the training objects (data/learning/grasps.jsonl from `python tools/learn_theory.py --stage collect --seed 0`; summary in docs/results/learning_data.json), 299 interpretations (a grasp that served an afforded task), 50 dropped (no rule for the served part).
% Made by: python tools/learn_theory.py --stage fit
% Clauses without data keep their hand-written values. Do not edit: rerun the command (tg_drake/logic/learning.py says what is tunable and why).
%
% Task-dependent grasp model, specific variant (paper IV-C): CP-events that make a part graspable
% for a task, given the object's super-category, pose and containment. One block per super-category
% (the four that partition the categories: dish, kitchen_container, canister, tool) and task; the
% causal probability is how suitable the part is. Blocks marked "paper" are the paper's; the rest are
% ours (rules/README.md, table 5). A part is only grasped if it was observed (part/2 in the body).


% ---- dish (cup, glass, bowl) ----
% pass, upright, full (paper)
0.9846::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upright), full(X), part(middle, X).
0.0077::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upright), full(X), part(top, X).
0.0143::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upright), full(X), part(handle, X).
% pass, upright, empty (paper)
0.324::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upright), empty(X), part(bottom, X).
0.344::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upright), empty(X), part(middle, X).
0.328::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upright), empty(X), part(top, X).
% pass, upside down (paper)
0.281::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upsidedown), part(bottom, X).
0.3087::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upsidedown), part(middle, X).
0.4103::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, upsidedown), part(top, X).
% pass, sideways (ours)
0.3296::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, sideways), part(middle, X).
0.2926::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, sideways), part(bottom, X).
0.3778::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, dish), pose(X, sideways), part(top, X).
% pourOut, full (paper: not(empty(X)))
1.0::grasp(X, T, middle) :- affords(X, T), isa_task(T, pour_out), kind(X, dish), full(X), part(middle, X).
% pourIn, empty (paper)
1.0::grasp(X, T, middle) :- affords(X, T), isa_task(T, pour_in), kind(X, dish), empty(X), part(middle, X).
% p&pIn, sideways (paper)
0.9778::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_in), kind(X, dish), pose(X, sideways), part(middle, X).
0.0222::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_in), kind(X, dish), pose(X, sideways), part(bottom, X).
% p&pIn, upright (ours)
0.9919::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_in), kind(X, dish), pose(X, upright), part(middle, X).
0.0081::grasp(X, T, top) :- affords(X, T), isa_task(T, pp_in), kind(X, dish), pose(X, upright), part(top, X).
% p&pIn, upside down (ours)
0.9833::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_in), kind(X, dish), pose(X, upsidedown), part(middle, X).
0.0167::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_in), kind(X, dish), pose(X, upsidedown), part(bottom, X).
% p&pOn, upright (ours)
0.6649::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_on), kind(X, dish), pose(X, upright), part(middle, X).
0.3351::grasp(X, T, top) :- affords(X, T), isa_task(T, pp_on), kind(X, dish), pose(X, upright), part(top, X).
% p&pOn, sideways (ours)
0.5148::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_on), kind(X, dish), pose(X, sideways), part(middle, X).
0.4852::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_on), kind(X, dish), pose(X, sideways), part(bottom, X).
% p&pOn, upside down (ours)
0.5056::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_on), kind(X, dish), pose(X, upsidedown), part(middle, X).
0.4944::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_on), kind(X, dish), pose(X, upsidedown), part(bottom, X).

% ---- kitchen_container (pan, pot): held by the handle (ours) ----
% pass, upright, empty
0.6::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, upright), empty(X), part(handle, X).
0.3::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, upright), empty(X), part(top, X).
0.1::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, upright), empty(X), part(middle, X).
% pass, upright, full
0.8::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, upright), full(X), part(handle, X).
0.1::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, upright), full(X), part(middle, X).
% pass, sideways
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, sideways), part(handle, X).
0.3::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, sideways), part(middle, X).
% pass, upside down
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, upsidedown), part(handle, X).
0.3::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), pose(X, upsidedown), part(bottom, X).
% pourIn, empty
0.8::grasp(X, T, handle) :- affords(X, T), isa_task(T, pour_in), kind(X, kitchen_container), empty(X), part(handle, X).
0.2::grasp(X, T, middle) :- affords(X, T), isa_task(T, pour_in), kind(X, kitchen_container), empty(X), part(middle, X).
% p&pIn, upright
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_in), kind(X, kitchen_container), pose(X, upright), part(handle, X).
0.3::grasp(X, T, top) :- affords(X, T), isa_task(T, pp_in), kind(X, kitchen_container), pose(X, upright), part(top, X).
% p&pIn, sideways
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_in), kind(X, kitchen_container), pose(X, sideways), part(handle, X).
0.3::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_in), kind(X, kitchen_container), pose(X, sideways), part(middle, X).
% p&pIn, upside down
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_in), kind(X, kitchen_container), pose(X, upsidedown), part(handle, X).
0.3::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_in), kind(X, kitchen_container), pose(X, upsidedown), part(bottom, X).
% p&pOn, upright
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_on), kind(X, kitchen_container), pose(X, upright), part(handle, X).
0.3::grasp(X, T, top) :- affords(X, T), isa_task(T, pp_on), kind(X, kitchen_container), pose(X, upright), part(top, X).
% p&pOn, sideways
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_on), kind(X, kitchen_container), pose(X, sideways), part(handle, X).
0.3::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_on), kind(X, kitchen_container), pose(X, sideways), part(middle, X).
% p&pOn, upside down
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_on), kind(X, kitchen_container), pose(X, upsidedown), part(handle, X).
0.3::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_on), kind(X, kitchen_container), pose(X, upsidedown), part(bottom, X).

% ---- canister (bottle, can): held round the body (ours) ----
% pass, upright
0.3495::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, upright), part(middle, X).
0.3121::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, upright), part(top, X).
0.3383::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, upright), part(bottom, X).
% pass, sideways
0.4561::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, sideways), part(middle, X).
0.1397::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, sideways), part(top, X).
0.4042::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, sideways), part(bottom, X).
% pass, upside down
0.3586::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, upsidedown), part(middle, X).
0.3241::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, upsidedown), part(bottom, X).
0.3172::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, canister), pose(X, upsidedown), part(top, X).
% pourOut, full
0.9925::grasp(X, T, middle) :- affords(X, T), isa_task(T, pour_out), kind(X, canister), full(X), part(middle, X).
0.0075::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pour_out), kind(X, canister), full(X), part(bottom, X).
% p&pIn, upright
0.7292::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_in), kind(X, canister), pose(X, upright), part(middle, X).
0.2708::grasp(X, T, top) :- affords(X, T), isa_task(T, pp_in), kind(X, canister), pose(X, upright), part(top, X).
% p&pIn, sideways
0.7537::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_in), kind(X, canister), pose(X, sideways), part(middle, X).
0.2463::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_in), kind(X, canister), pose(X, sideways), part(bottom, X).
% p&pIn, upside down
0.7397::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_in), kind(X, canister), pose(X, upsidedown), part(middle, X).
0.2603::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_in), kind(X, canister), pose(X, upsidedown), part(bottom, X).
% p&pOn, upright
0.5232::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_on), kind(X, canister), pose(X, upright), part(middle, X).
0.4768::grasp(X, T, top) :- affords(X, T), isa_task(T, pp_on), kind(X, canister), pose(X, upright), part(top, X).
% p&pOn, sideways
0.5222::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_on), kind(X, canister), pose(X, sideways), part(middle, X).
0.4778::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_on), kind(X, canister), pose(X, sideways), part(bottom, X).
% p&pOn, upside down
0.5069::grasp(X, T, middle) :- affords(X, T), isa_task(T, pp_on), kind(X, canister), pose(X, upsidedown), part(middle, X).
0.4931::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pp_on), kind(X, canister), pose(X, upsidedown), part(bottom, X).

% ---- tool (hammer, knife, screwdriver, cooking_tool) ----
% pass: by the usable area, the receiver takes the handle (paper, IV)
0.9692::grasp(X, T, usable_area) :- affords(X, T), isa_task(T, pass), kind(X, tool), part(usable_area, X).
0.0308::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, tool), part(handle, X).
% p&pInSideways (ours)
0.8::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_in_sideways), kind(X, tool), part(handle, X).
0.2::grasp(X, T, usable_area) :- affords(X, T), isa_task(T, pp_in_sideways), kind(X, tool), part(usable_area, X).
% p&pOn (ours)
0.8::grasp(X, T, handle) :- affords(X, T), isa_task(T, pp_on), kind(X, tool), part(handle, X).
0.2::grasp(X, T, usable_area) :- affords(X, T), isa_task(T, pp_on), kind(X, tool), part(usable_area, X).
