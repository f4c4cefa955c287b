% LEARNED category model: the probabilities of category_specific.pl fitted by ProbLog's learning from interpretations (EM, 24 iterations, log-likelihood -217.46),
% starting from the hand-written values (worth 2 interpretations as a prior); data: the training objects of the library in every pose (66 labelled interpretations: parts, pose, handles, category).
% Made by: python tools/learn_theory.py --stage fit
% Clauses without data keep their hand-written values. Do not edit: rerun the command (tg_drake/logic/learning.py says what is tunable and why).
%
% Category model, specific variant (paper IV-C): CP-events from the observed parts and pose to
% categories, and the part signatures that rule a category out (incompatible/1, conditioned on
% false by every query). Rules marked "ours" complete the paper's examples.

% Three body parts, no handle (paper).
0.25::cat(X, glass); 0.25::cat(X, bowl); 0.5::some(X, canister) :- tmb(X), no_handle(X), pose(X, upright).
0.3182::cat(X, glass); 0.0455::cat(X, bowl); 0.6363::some(X, canister) :- tmb(X), no_handle(X), pose(X, sideways).
0.3327::cat(X, glass); 0.3327::cat(X, bowl); 0.3327::cat(X, can) :- tmb(X), no_handle(X), pose(X, upsidedown).
% Exactly one handle (paper: upright; ours: upside down, and sideways where a pan does not rest).
0.5625::cat(X, cup); 0.4375::cat(X, pan) :- tmb(X), one_handle(X), pose(X, upright).
0.5625::cat(X, cup); 0.4375::cat(X, pan) :- tmb(X), one_handle(X), pose(X, upsidedown).
cat(X, cup) :- tmb(X), one_handle(X), pose(X, sideways).
% Two handles (ours).
cat(X, pot) :- tmb(X), two_handles(X).
% A usable area and a handle, lying sideways (paper).
some(X, tool) :- part(usable_area, X), part(handle, X), pose(X, sideways).

% Part signatures that rule a category out (ours; the paper's cup example needs the first and the
% fourth: "can and pot become 0").
incompatible(X) :- kind(X, canister), part(handle, X).
incompatible(X) :- kind(X, canister), interior_seen(X).
incompatible(X) :- cat(X, glass), part(handle, X).
incompatible(X) :- cat(X, bowl), part(handle, X).
incompatible(X) :- cat(X, pot), one_handle(X).
incompatible(X) :- cat(X, cup), two_handles(X).
incompatible(X) :- cat(X, pan), two_handles(X).
incompatible(X) :- kind(X, tool), \+ part(usable_area, X).
incompatible(X) :- kind(X, container), part(usable_area, X).
