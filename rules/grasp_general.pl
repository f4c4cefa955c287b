% Task-dependent grasp model, general variant (paper IV-C): the specific model generalised over pose
% and containment and over related tasks (pour = pourIn, pourOut; place = p&pIn, p&pOn), so far
% fewer rules. The dish/pass block is the paper's; the rest are ours (rules/README.md, table 6).


% ---- dish ----
% pass (paper)
0.1::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, dish), part(bottom, X).
0.6::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, dish), part(middle, X).
0.2::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, dish), part(top, X).
0.1::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, dish), part(handle, X).
% pour
1.0::grasp(X, T, middle) :- affords(X, T), isa_task(T, pour), kind(X, dish), part(middle, X).
% place
0.7::grasp(X, T, middle) :- affords(X, T), isa_task(T, place), kind(X, dish), part(middle, X).
0.15::grasp(X, T, top) :- affords(X, T), isa_task(T, place), kind(X, dish), part(top, X).
0.15::grasp(X, T, bottom) :- affords(X, T), isa_task(T, place), kind(X, dish), part(bottom, X).

% ---- kitchen_container ----
% pass
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), part(handle, X).
0.2::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), part(top, X).
0.1::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, kitchen_container), part(middle, X).
% pour
0.8::grasp(X, T, handle) :- affords(X, T), isa_task(T, pour), kind(X, kitchen_container), part(handle, X).
0.2::grasp(X, T, middle) :- affords(X, T), isa_task(T, pour), kind(X, kitchen_container), part(middle, X).
% place
0.7::grasp(X, T, handle) :- affords(X, T), isa_task(T, place), kind(X, kitchen_container), part(handle, X).
0.15::grasp(X, T, top) :- affords(X, T), isa_task(T, place), kind(X, kitchen_container), part(top, X).
0.15::grasp(X, T, bottom) :- affords(X, T), isa_task(T, place), kind(X, kitchen_container), part(bottom, X).

% ---- canister ----
% pass
0.7::grasp(X, T, middle) :- affords(X, T), isa_task(T, pass), kind(X, canister), part(middle, X).
0.15::grasp(X, T, top) :- affords(X, T), isa_task(T, pass), kind(X, canister), part(top, X).
0.15::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pass), kind(X, canister), part(bottom, X).
% pour
0.8::grasp(X, T, middle) :- affords(X, T), isa_task(T, pour), kind(X, canister), part(middle, X).
0.2::grasp(X, T, bottom) :- affords(X, T), isa_task(T, pour), kind(X, canister), part(bottom, X).
% place
0.7::grasp(X, T, middle) :- affords(X, T), isa_task(T, place), kind(X, canister), part(middle, X).
0.15::grasp(X, T, top) :- affords(X, T), isa_task(T, place), kind(X, canister), part(top, X).
0.15::grasp(X, T, bottom) :- affords(X, T), isa_task(T, place), kind(X, canister), part(bottom, X).

% ---- tool ----
% pass (paper, IV)
0.8::grasp(X, T, usable_area) :- affords(X, T), isa_task(T, pass), kind(X, tool), part(usable_area, X).
0.2::grasp(X, T, handle) :- affords(X, T), isa_task(T, pass), kind(X, tool), part(handle, X).
% place
0.8::grasp(X, T, handle) :- affords(X, T), isa_task(T, place), kind(X, tool), part(handle, X).
0.2::grasp(X, T, usable_area) :- affords(X, T), isa_task(T, place), kind(X, tool), part(usable_area, X).
