% Category model, shared by both variants (paper IV-C): CP-events that spread a super-category,
% concluded by a category rule, over the categories below it. Causal probabilities follow the
% number of leaf categories under each child ("0.5::can(X); 0.5::bottle(X) <- canister(X)").
% some(X, S): a rule concluded that X is some S without deciding which category. It only spreads
% down; kind/2 (object_ontology.pl) goes up, so a can is never made a bottle.

7/11::some(X, container); 4/11::some(X, tool) :- some(X, object).
5/7::some(X, open_container); 2/7::some(X, canister) :- some(X, container).
2/5::some(X, kitchen_container); 3/5::some(X, dish) :- some(X, open_container).
0.5::cat(X, pan); 0.5::cat(X, pot) :- some(X, kitchen_container).
1/3::cat(X, cup); 1/3::cat(X, glass); 1/3::cat(X, bowl) :- some(X, dish).
0.5::cat(X, can); 0.5::cat(X, bottle) :- some(X, canister).
0.25::cat(X, hammer); 0.25::cat(X, knife); 0.25::cat(X, screwdriver); 0.25::cat(X, cooking_tool) :- some(X, tool).
