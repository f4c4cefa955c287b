"""tg_drake_models: robot, table and object-library model files (package://tg_drake_models/...)."""
