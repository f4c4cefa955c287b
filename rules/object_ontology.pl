% Object ontology (paper IV-B): the 11 object categories and the super-categories above them.
% subclass(C, S): C sits directly below S. The tree is our reading of the paper's missing figure
% (rules/README.md, table 1): object > container | tool; container > openContainer | canister;
% openContainer > kitchenContainer | dish. Atoms are snake_case (kitchenContainer -> kitchen_container).
% kind(X, S) is the paper's upward mapping (canister(X) :- can(X). container(X) :- canister(X). ...).

leaf(pan). leaf(pot). leaf(cup). leaf(glass). leaf(bowl). leaf(bottle). leaf(can).
leaf(hammer). leaf(knife). leaf(screwdriver). leaf(cooking_tool).

subclass(pan, kitchen_container).
subclass(pot, kitchen_container).
subclass(cup, dish).
subclass(glass, dish).
subclass(bowl, dish).
subclass(bottle, canister).
subclass(can, canister).
subclass(hammer, tool).
subclass(knife, tool).
subclass(screwdriver, tool).
subclass(cooking_tool, tool).
subclass(kitchen_container, open_container).
subclass(dish, open_container).
subclass(open_container, container).
subclass(canister, container).
subclass(container, object).
subclass(tool, object).

% isa(C, S): category C is S or lies below S.
isa(C, C) :- leaf(C).
isa(C, S) :- subclass(C, S).
isa(C, S) :- subclass(C, M), isa(M, S).

% kind(X, S): object X belongs to (super-)category S.
kind(X, S) :- cat(X, C), isa(C, S).
