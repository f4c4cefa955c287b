% Constraints (paper IV-C): pre-grasps that must not happen. violation(X, T) holds in a world where
% a part chosen for task T breaks one; the part query conditions on no violation, which is the
% paper's "false :- ..." (a violating pre-grasp gets probability 0, the others keep their ratios).

% Impossible affordance (paper).
violation(X, T) :- grasp(X, T, R), impossible(X, T), part(R, X).
% Collision of the gripper at a part (paper; collision/1 comes from the planner).
violation(X, T) :- grasp(X, T, R), part(R, X), collision(R).
% No grasp on the part would hold (ours; no_hold/1 comes from the feasibility stage: every pose on
% the part is more likely to slip than to hold). The part is not unreachable: it is told apart.
violation(X, T) :- grasp(X, T, R), part(R, X), no_hold(R).
% An upside-down pan gets no grasp (paper).
violation(X, T) :- grasp(X, T, R), pose(X, upsidedown), cat(X, pan), part(R, X).
