% Constraints (paper IV-C): pre-grasps that must not happen. violation(X, T) holds in a world where
% a part chosen for task T breaks one; the part query conditions on no violation, which is the
% paper's "false :- ..." (a violating pre-grasp gets probability 0, the others keep their ratios).

% Impossible affordance (paper).
violation(X, T) :- grasp(X, T, R), impossible(X, T), part(R, X).
% Collision of the gripper at a part (paper; collision/1 comes from the planner).
violation(X, T) :- grasp(X, T, R), part(R, X), collision(R).
% An upside-down pan gets no grasp (paper).
violation(X, T) :- grasp(X, T, R), pose(X, upsidedown), cat(X, pan), part(R, X).
