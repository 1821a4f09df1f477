mod petsc;
fn main() {}
