pub mod check;
pub mod info;
