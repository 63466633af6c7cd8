//! The application logic, free of any HAL.
