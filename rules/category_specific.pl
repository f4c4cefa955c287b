% Category model, specific variant (paper IV-C): CP-events from the observed parts and pose to
% categories, and the part signatures that rule a category out (incompatible/1, conditioned on
% false by every query). Rules marked "ours" complete the paper's examples.

% Three body parts, no handle (paper).
0.25::cat(X, glass); 0.25::cat(X, bowl); 0.5::some(X, canister) :- tmb(X), no_handle(X), pose(X, upright).
0.25::cat(X, glass); 0.25::cat(X, bowl); 0.5::some(X, canister) :- tmb(X), no_handle(X), pose(X, sideways).
0.33::cat(X, glass); 0.33::cat(X, bowl); 0.33::cat(X, can) :- tmb(X), no_handle(X), pose(X, upsidedown).
% Exactly one handle (paper: upright; ours: upside down, and sideways where a pan does not rest).
0.75::cat(X, cup); 0.25::cat(X, pan) :- tmb(X), one_handle(X), pose(X, upright).
0.75::cat(X, cup); 0.25::cat(X, pan) :- tmb(X), one_handle(X), pose(X, upsidedown).
cat(X, cup) :- tmb(X), one_handle(X), pose(X, sideways).
% Two handles (ours).
cat(X, pot) :- tmb(X), two_handles(X).
% A usable area and a handle, lying sideways (paper).
some(X, tool) :- part(usable_area, X), part(handle, X), pose(X, sideways).

% Part signatures that rule a category out (ours; the paper's cup example needs the first and the
% fourth: "can and pot become 0").
incompatible(X) :- kind(X, canister), part(handle, X).
incompatible(X) :- kind(X, canister), interior_seen(X).
% A dish standing upright shows its inside to the camera above the table (ours): perception
% looking for it and not seeing it rules a dish out but for its misses, P(inside unseen | dish
% upright) = 1/47 (Laplace on 0 of 45 training views of cups, glasses and bowls upright through
% the D415 model: `tools/measure_perception.py --fit`).
0.979::incompatible(X) :- kind(X, dish), pose(X, upright), interior_hidden(X).
incompatible(X) :- cat(X, glass), part(handle, X).
incompatible(X) :- cat(X, bowl), part(handle, X).
incompatible(X) :- cat(X, pot), one_handle(X).
incompatible(X) :- cat(X, cup), two_handles(X).
incompatible(X) :- cat(X, pan), two_handles(X).
incompatible(X) :- kind(X, tool), \+ part(usable_area, X).
incompatible(X) :- kind(X, container), part(usable_area, X).
