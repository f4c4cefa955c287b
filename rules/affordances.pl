% Object-task affordances (paper IV-B): possible and impossible tasks per (super-)category, the
% common-sense exceptions, and affords/2. Entries marked "ours" complete the paper's missing table
% (rules/README.md, table 3).

% Possible tasks (paper).
possible(X, T) :- kind(X, object), isa_task(T, pass).
possible(X, T) :- kind(X, container), isa_task(T, pour).
possible(X, T) :- kind(X, object), isa_task(T, pp_on).
possible(X, T) :- kind(X, container), isa_task(T, pp_in).
possible(X, T) :- kind(X, tool), isa_task(T, pp_in_sideways).

% Impossible tasks (paper).
impossible(X, T) :- kind(X, canister), isa_task(T, pour_in).
impossible(X, T) :- kind(X, kitchen_container), isa_task(T, pour_out).
% Common-sense exceptions (paper).
impossible(X, T) :- cat(X, pan), full(X), isa_task(T, pass).
impossible(X, T) :- kind(X, container), full(X), isa_task(T, pp_in_upsidedown).
% Common-sense exceptions (ours): nothing can be poured into a full container or out of an empty
% one; an open container is not stored lying on its side.
impossible(X, T) :- kind(X, container), full(X), isa_task(T, pour_in).
impossible(X, T) :- kind(X, container), empty(X), isa_task(T, pour_out).
impossible(X, T) :- kind(X, open_container), isa_task(T, pp_in_sideways).

% Unusual tasks (ours, the paper's footnote: "in the case of task prediction, we use the
% affordance rules with a high equal probability"): possible, but a robot is rarely asked to do
% them. A dish is filled where it stands, and stored upright.
unusual(X, T) :- kind(X, dish), isa_task(T, pour_in).
unusual(X, T) :- kind(X, dish), isa_task(T, pp_in_upsidedown).

% The probability is one of task prediction: it weighs an unusual task only when the task is
% inferred (task_given/0, an observation, false). A task the user gives is afforded or not: a
% glass asked to be stored upside down is grasped for it with the grasp model's odds, undiscounted.
affords(X, T) :- possible(X, T), \+ impossible(X, T), \+ unusual(X, T).
affords(X, T) :- possible(X, T), \+ impossible(X, T), unusual(X, T), task_given.
0.1::affords(X, T) :- possible(X, T), \+ impossible(X, T), unusual(X, T), \+ task_given.
