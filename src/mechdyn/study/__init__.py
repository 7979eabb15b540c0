"""Design studies: many variants of one model file, analysed and tabulated."""
