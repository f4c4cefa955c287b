% Observation vocabulary (paper IV-A): predicates derived from the perceived parts.
% The observations themselves (part/2, pose/2, empty/1, full/1, handle_pair/1, collision/1,
% no_hold/1, interior_seen/1, interior_hidden/1, the category prior on cat/2, the task or task
% prior on task/1 and task_given/0, true when the task is given rather than inferred) enter from
% Python as data: tg_drake/logic/observations.py. The object under query is the
% constant o.

% tmb(X): X shows the three body parts of a container.
tmb(X) :- part(top, X), part(middle, X), part(bottom, X).
no_handle(X) :- \+ part(handle, X).
% handle_pair(X): perception saw the handle part as two handles on opposite sides (a pot).
one_handle(X) :- part(handle, X), \+ handle_pair(X).
two_handles(X) :- part(handle, X), handle_pair(X).
% interior_seen(X) (ours): the camera saw X's inside through a wide opening (inner walls facing the
% axis): X is an open container, not a closed can or a bottle with a narrow neck.
% interior_hidden(X) (ours): perception looked for X's inside and did not see it (for a perceived
% object, the complement of interior_seen; absent from an observations file unless given).
