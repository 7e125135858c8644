//! Training the length models and writing the tables the firmware compiles.

pub mod codegen;
pub mod cross_validation;
pub mod fit;
pub mod training;
pub mod training_set;
