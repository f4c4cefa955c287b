% The receiver of a pass (ours, issue 21): the part of X that the person (in simulation, the second
% WSG) taking it from the robot's hand takes, given the part the robot holds it by, held(X, Part).
% The robot's own grasp stays grasp(X, T, Part) of the grasp model; this file is a separate,
% small program: tg_drake/logic/receive.py loads it with object_ontology.pl, adds the category
% distribution as an annotated disjunction over cat(o, C) and held(o, Part) as a fact, and asks
% receive(o, Part) for every part. Within a kind the heads are exclusive, the kinds are
% exclusive through cat/2, so the answers sum to 1 over the parts (before the parts the object
% does not show are dropped, rules/README.md "The receiver of a pass").
%
% A person takes a tool by its handle (the paper's pass, IV: the robot holds the usable area so
% that the handle is free); when the robot holds the handle, by the handle's free end beside the
% robot's fingers where there is room (the feasibility check decides), else by the head or blade. A pot or pan is taken by its handle, or by its body when the robot holds the
% handle. A cup, glass or bowl is taken round its body, by the side the robot leaves free, or
% under it or by its rim. A bottle or can is taken round its body, or by its top or bottom end.

% ---- tool ----
0.9::receive(X, handle); 0.1::receive(X, usable_area) :- kind(X, tool), held(X, usable_area).
0.7::receive(X, handle); 0.3::receive(X, usable_area) :- kind(X, tool), held(X, handle).

% ---- kitchen_container (pan, pot) ----
0.5::receive(X, middle); 0.3::receive(X, top); 0.2::receive(X, handle) :-
    kind(X, kitchen_container), held(X, handle).
0.8::receive(X, handle); 0.2::receive(X, middle) :- kind(X, kitchen_container), held(X, middle).
0.8::receive(X, handle); 0.2::receive(X, middle) :- kind(X, kitchen_container), held(X, top).
0.8::receive(X, handle); 0.2::receive(X, middle) :- kind(X, kitchen_container), held(X, bottom).

% ---- dish (cup, glass, bowl) ----
0.8::receive(X, middle); 0.2::receive(X, top) :- kind(X, dish), held(X, handle).
0.5::receive(X, middle); 0.3::receive(X, bottom); 0.2::receive(X, top) :-
    kind(X, dish), held(X, middle).
0.8::receive(X, middle); 0.2::receive(X, bottom) :- kind(X, dish), held(X, top).
0.8::receive(X, middle); 0.2::receive(X, top) :- kind(X, dish), held(X, bottom).

% ---- canister (bottle, can) ----
0.4::receive(X, middle); 0.4::receive(X, top); 0.2::receive(X, bottom) :-
    kind(X, canister), held(X, middle).
0.8::receive(X, middle); 0.2::receive(X, bottom) :- kind(X, canister), held(X, top).
0.8::receive(X, middle); 0.2::receive(X, top) :- kind(X, canister), held(X, bottom).
0.8::receive(X, middle); 0.2::receive(X, top) :- kind(X, canister), held(X, handle).
