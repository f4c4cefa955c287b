% Category model, general variant (paper IV-C): the specific heads replaced by super-categories,
% with the same bodies, and part signatures at the super-category level only. Rules marked "ours"
% complete the paper's examples.

% Three body parts, no handle (paper).
some(X, container) :- tmb(X), no_handle(X), pose(X, upright).
0.6::some(X, dish); 0.4::some(X, canister) :- tmb(X), no_handle(X), pose(X, sideways).
some(X, container) :- tmb(X), no_handle(X), pose(X, upsidedown).
% Exactly one handle, any pose (paper).
0.5::cat(X, cup); 0.5::some(X, kitchen_container) :- tmb(X), one_handle(X).
% Two handles (ours).
some(X, kitchen_container) :- tmb(X), two_handles(X).
% A usable area and a handle, any pose (ours: the paper's tool rule without the pose).
some(X, tool) :- part(usable_area, X), part(handle, X).

% Part signatures that rule a super-category out (ours).
incompatible(X) :- kind(X, canister), part(handle, X).
incompatible(X) :- kind(X, canister), interior_seen(X).
% A dish standing upright shows its inside to the camera above the table (ours): perception
% looking for it and not seeing it rules a dish out but for its misses, P(inside unseen | dish
% upright) = 1/47 (Laplace on 0 of 45 training views of cups, glasses and bowls upright through
% the D415 model: `tools/measure_perception.py --fit`).
0.979::incompatible(X) :- kind(X, dish), pose(X, upright), interior_hidden(X).
incompatible(X) :- kind(X, tool), \+ part(usable_area, X).
incompatible(X) :- kind(X, container), part(usable_area, X).
