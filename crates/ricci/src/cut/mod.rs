//! Cut graphs and canonical fundamental group generators (paper 001 App. A, 002 §6.2.2.1).
