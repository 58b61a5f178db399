//! `lbdem-mpi` outside a launcher refuses before reading anything, naming how to start it, with
//! no stack backtrace under RUST_BACKTRACE=1; the MPI run itself is compared with `lbdem sweep`
//! by scripts/mpi-sweep-check.sh (CI).

use std::process::Command;

#[test]
fn without_a_launcher_it_refuses_and_names_mpirun() {
    let out = Command::new(env!("CARGO_BIN_EXE_lbdem-mpi"))
        .args(["sweep", "no-such-sweep.toml"])
        .env_remove("OMPI_COMM_WORLD_SIZE")
        .env_remove("PMI_SIZE")
        .env_remove("PMIX_RANK")
        .env_remove("MPI_LOCALNRANKS")
        .env("RUST_BACKTRACE", "1")
        .env_remove("RUST_LIB_BACKTRACE")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("mpirun -n N lbdem-mpi sweep no-such-sweep.toml") && err.contains("lbdem sweep"),
        "{err}"
    );
    assert!(
        !err.contains("backtrace"),
        "a refusal is a message, not a crash: {err}"
    );
}
