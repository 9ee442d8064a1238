//! `walkctl` as a library: the operations on stance sequences and on a running `walkd`.
