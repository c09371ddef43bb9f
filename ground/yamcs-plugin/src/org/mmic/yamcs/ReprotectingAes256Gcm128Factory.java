package org.mmic.yamcs;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;

import org.yamcs.ConfigurationException;
import org.yamcs.Spec;
import org.yamcs.YConfiguration;
import org.yamcs.security.sdls.SdlsSecurityAssociation;
import org.yamcs.security.sdls.SdlsSecurityAssociationFactory;
import org.yamcs.security.sdls.SecurityAssociationAes256Gcm128Factory;

/**
 * Creates {@link ReprotectingAes256Gcm128}: YAMCS's own AES-256-GCM SA (made by its own factory, with the same
 * options: keyFile, verifySeqNum, seqNumWindow, initialSeqNum) wrapped so that a COP-1 retransmission is protected
 * again from its plaintext. Found by YAMCS's ServiceLoader (META-INF/services); a link selects it with
 * {@code class: org.mmic.yamcs.ReprotectingAes256Gcm128Factory} in its {@code encryption} list.
 */
public class ReprotectingAes256Gcm128Factory implements SdlsSecurityAssociationFactory {
    private final SecurityAssociationAes256Gcm128Factory builtIn = new SecurityAssociationAes256Gcm128Factory();

    public ReprotectingAes256Gcm128Factory() {
    }

    @Override
    public Spec getSpec() {
        return builtIn.getSpec();
    }

    @Override
    public SdlsSecurityAssociation create(String instanceName, String linkName, short spi, YConfiguration args) {
        byte[] key;
        try {
            key = Files.readAllBytes(Path.of(args.getString("keyFile")));
        } catch (IOException e) {
            throw new ConfigurationException(e);
        }
        return new ReprotectingAes256Gcm128(builtIn.create(instanceName, linkName, spi, args), spi, key);
    }
}
